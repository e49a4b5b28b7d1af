"""The layouts the first start writes are ones the API itself would accept, unchanged."""

import sys

import pytest

from rover_web.layouts.defaults import DEFAULTS
from rover_web.layouts.schema import validate


@pytest.mark.parametrize("kind", sorted(DEFAULTS))
def test_each_default_layout_validates_as_it_is(kind):
    assert validate(DEFAULTS[kind]) == DEFAULTS[kind]


def test_importing_the_layouts_leaves_jsonschema_unloaded_until_a_validation():
    # Checked in a fresh interpreter: this one has validated above.
    import subprocess

    code = ("import sys, rover_web.layouts.store, rover_web.layouts.routes; "
            "print('jsonschema' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
