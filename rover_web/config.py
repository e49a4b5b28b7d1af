"""Every ROVER_WEB_* setting: its default, its type and a one-line meaning.

Settings are read, in order of increasing precedence, from the defaults below, a TOML file named
by the ROVER_WEB_CONFIG environment variable, ROVER_WEB_* environment variables, and the
test_config mapping given to create_app(). Every value is validated before anything starts, and
an unknown ROVER_WEB_* name is an error too: a typo must not silently fall back to a default on a
machine that drives a robot.
"""

from __future__ import annotations

import json
import math
import os
import re
import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from rover_web.core import robots
from rover_web.settings import SETTINGS, Setting  # noqa: F401 - Setting: part of this module's API

# The checkout (or install) root: templates/, static/ and map_files/ are found from here.
ROOT = Path(__file__).resolve().parent.parent


def repo_path(value: str | None) -> Path | None:
    """A path setting as a path: relative ones start at the repository root; empty means none."""
    if not value:
        return None
    path = Path(value).expanduser()
    return path if path.is_absolute() else ROOT / path


PREFIX = "ROVER_WEB_"
CONFIG_FILE_VAR = "ROVER_WEB_CONFIG"


class ConfigError(ValueError):
    """A setting is missing, malformed or out of range; the message names the key."""


TOPIC_PATTERN = re.compile(r"/?[A-Za-z_~{][A-Za-z0-9_{}~]*(/[A-Za-z_{][A-Za-z0-9_{}]*)*\Z")


_BY_NAME = {PREFIX + s.name: s for s in SETTINGS}
# The settings that name one ROS topic: core/robots.settings_for resolves them under a namespace.
TOPIC_KEYS = tuple(PREFIX + s.name for s in SETTINGS if s.kind in ("topic", "optional_topic"))


def defaults() -> dict[str, Any]:
    return {PREFIX + s.name: _copy(s.default) for s in SETTINGS}


def _copy(value: Any) -> Any:
    return list(value) if isinstance(value, list) else value


def _from_text(setting: Setting, text: str) -> Any:
    """Environment variables are text: turn one into the setting's type before validation."""
    kind = setting.kind
    stripped = text.strip()
    if kind.startswith("optional_") and stripped == "":
        return None
    if kind == "bool":
        lowered = stripped.lower()
        if lowered in ("1", "true", "yes", "on"):
            return True
        if lowered in ("0", "false", "no", "off"):
            return False
        return text
    if kind in ("int", "optional_int"):
        try:
            return int(stripped)
        except ValueError:
            return text
    if kind == "float":
        try:
            return float(stripped)
        except ValueError:
            return text
    if kind == "robots":
        stripped = robots.from_text(stripped)
        if not isinstance(stripped, str):
            return stripped
    if kind in ("list", "robots"):
        if stripped.startswith("["):
            try:
                return json.loads(stripped)
            except json.JSONDecodeError:
                return text
        return [part.strip() for part in stripped.split(",") if part.strip()]
    return text


def _check(setting: Setting, value: Any, source: str) -> Any:
    name = PREFIX + setting.name
    kind = setting.kind

    def fail(expected: str) -> ConfigError:
        return ConfigError(f"{name}: expected {expected}, got {value!r} (from {source})")

    if kind.startswith("optional_"):
        if value is None:
            return None
        kind = kind[len("optional_"):]
    if kind == "bool":
        if not isinstance(value, bool):
            raise fail("true or false")
        return value
    if kind in ("int", "float"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise fail("an integer" if kind == "int" else "a number")
        if kind == "int" and (isinstance(value, float) and not value.is_integer()):
            raise fail("an integer")
        if not math.isfinite(value):
            raise fail("a finite number")
        if setting.low is not None and value < setting.low or setting.high is not None and value > setting.high:
            raise fail(f"a value from {setting.low:g} to {setting.high:g}")
        return int(value) if kind == "int" else float(value)
    if kind == "robots":
        try:
            parsed = robots.parse(value)
        except robots.RobotsError as exc:
            raise ConfigError(f"{name}: {exc} (from {source})") from None
        return [r.as_dict() for r in parsed] if value else []
    if kind == "list":
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise fail("a list of strings")
        return list(value)
    if kind in ("str", "topic"):
        if not isinstance(value, str) or (kind == "str" and not value and setting.default):
            raise fail("a non-empty string")
        if setting.choices and value not in setting.choices:
            raise fail("one of " + ", ".join(setting.choices))
        if kind == "topic" and not TOPIC_PATTERN.match(value):
            raise fail("a ROS topic name such as /cmd_vel")
        return value
    raise AssertionError(f"unknown setting kind {setting.kind}")  # a bug in SETTINGS, not user input


def _apply(merged: dict[str, Any], values: Mapping[str, Any], source: str, convert: Callable | None) -> None:
    for key, value in values.items():
        if not key.startswith(PREFIX) or key == CONFIG_FILE_VAR:
            continue
        setting = _BY_NAME.get(key)
        if setting is None:
            raise ConfigError(f"{key}: unknown setting (from {source}); see README.md for the list")
        merged[key] = _check(setting, convert(setting, value) if convert else value, source)


def load(test_config: Mapping[str, Any] | None = None, environ: Mapping[str, str] | None = None) -> dict[str, Any]:
    """Return every ROVER_WEB_* setting, validated; raise ConfigError naming the first bad key."""
    environ = os.environ if environ is None else environ
    merged = defaults()
    path = (test_config or {}).get(CONFIG_FILE_VAR) or environ.get(CONFIG_FILE_VAR)
    if path:
        try:
            with open(path, "rb") as fh:
                from_file = tomllib.load(fh)
        except OSError as exc:
            raise ConfigError(f"{CONFIG_FILE_VAR}: cannot read {path}: {exc.strerror}") from None
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{CONFIG_FILE_VAR}: {path} is not valid TOML: {exc}") from None
        _apply(merged, from_file, f"config file {path}", None)
    _apply(merged, {k: v for k, v in environ.items() if k.startswith(PREFIX)}, "environment", _from_text)
    if test_config:
        _apply(merged, test_config, "create_app(test_config)", None)
    if bool(merged[PREFIX + "TLS_CERT"]) != bool(merged[PREFIX + "TLS_KEY"]):
        raise ConfigError("ROVER_WEB_TLS_CERT and ROVER_WEB_TLS_KEY go together: set both for HTTPS, or neither")
    return merged
