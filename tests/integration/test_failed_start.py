"""A create_app that fails part-way (a feature's bad setting) stops what it had started."""

import threading
import time

import pytest

from rover_web.config import ConfigError


def test_a_feature_that_fails_to_start_leaves_no_thread_behind(app_factory, tmp_path):
    bad = tmp_path / "panels.toml"
    bad.write_text("[panels.x]\ntitle = 1\n")
    before = {t.ident for t in threading.enumerate()}
    with pytest.raises(ConfigError):
        app_factory(ROVER_WEB_PANELS_FILE=str(bad))
    time.sleep(0.3)
    left = [t.name for t in threading.enumerate() if t.ident not in before and t.is_alive()]
    assert left == [], left
