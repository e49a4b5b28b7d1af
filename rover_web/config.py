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
from dataclasses import dataclass
from typing import Any, Callable, Mapping

PREFIX = "ROVER_WEB_"
CONFIG_FILE_VAR = "ROVER_WEB_CONFIG"


class ConfigError(ValueError):
    """A setting is missing, malformed or out of range; the message names the key."""


@dataclass(frozen=True)
class Setting:
    name: str
    default: Any
    kind: str  # str | int | float | bool | list | topic | optional_str | optional_int | optional_topic
    meaning: str
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] | None = None


_TOPIC_RE = re.compile(r"^/?[A-Za-z_~{][A-Za-z0-9_{}~]*(/[A-Za-z_{][A-Za-z0-9_{}]*)*$")

SETTINGS: tuple[Setting, ...] = (
    # --- process and ROS node ---
    Setting("NODE_NAME", "rover_web", "str", "name of the app's ROS 2 node"),
    Setting("ROS_DOMAIN_ID", None, "optional_int",
            "ROS domain id for the app's node; unset uses ROS_DOMAIN_ID from the environment (or 0)", 0, 232),
    Setting("HOST", "127.0.0.1", "str",
            "address `python -m rover_web.demo` and gunicorn.conf.py bind to; 0.0.0.0 exposes the GUI to the network"),
    Setting("PORT", 5000, "int", "port `python -m rover_web.demo` and gunicorn.conf.py listen on", 1, 65535),
    Setting("SHUTDOWN_TIMEOUT_S", 2.0, "float", "how long shutdown waits for the executor thread", 0.1, 30),
    Setting("DB_PATH", None, "optional_str",
            "SQLite database file; unset means rover_web.sqlite3 in the Flask instance folder"),
    # --- HTTP protection ---
    Setting("TRUSTED_HOSTS", ["127.0.0.1", "localhost", "::1"], "list",
            "Host header values accepted (port ignored; '.example.org' matches subdomains); guards DNS rebinding"),
    Setting("ALLOWED_ORIGINS", [], "list",
            "extra Origins (scheme://host:port) allowed to change state, besides the page's own origin"),
    Setting("MAX_BODY_BYTES", 262144, "int", "largest request body accepted (413 beyond)", 1024, 64 * 1024 * 1024),
    # --- live events and link health ---
    Setting("SSE_KEEPALIVE_S", 10.0, "float", "seconds between SSE keep-alive comments (at most 15)", 0.05, 15),
    Setting("SSE_RETRY_MS", 1000, "int", "reconnect delay the SSE stream asks browsers to use", 100, 60000),
    Setting("SSE_MAX_CLIENTS", 256, "int", "most SSE streams served at once (503 beyond)", 1, 4096),
    Setting("STATUS_PERIOD_S", 1.0, "float", "how often the `status` channel is refreshed", 0.1, 60),
    Setting("STALE_AFTER_S", 2.0, "float", "a topic with no message for this long is shown stale", 0.1, 3600),
    Setting("LINK_TOPICS", ["/odom"], "list",
            "topics whose freshness defines the server-robot link in the health bar"),
    Setting("ODOM_TOPIC", "/odom", "topic", "nav_msgs/Odometry the dashboard shows speed from"),
    # --- teleop ---
    Setting("CMD_VEL_TOPIC", "/cmd_vel", "topic", "velocity command topic"),
    Setting("CMD_VEL_STAMPED", False, "bool",
            "publish geometry_msgs/TwistStamped instead of Twist (Jazzy's diff_drive_controller wants it)"),
    Setting("CMD_VEL_FRAME_ID", "base_link", "str", "frame_id of TwistStamped commands"),
    Setting("MAX_LINEAR_MPS", 5.0, "float", "linear speed at full joystick deflection (m/s)", 0.0, 100),
    Setting("MAX_ANGULAR_RPS", 2.0, "float", "turn rate at full joystick deflection (rad/s)", 0.0, 100),
    # --- scan the code ---
    Setting("LIGHT_SEQUENCE_TOPIC", "/light_sequence", "topic",
            "std_msgs/String colour names from the light tower detector (Scan the Code)"),
    Setting("LIGHT_SEQUENCE_QOS", "default", "str",
            "QoS of that subscription: default (reliable) or sensor_data (best effort, for best-effort detectors)",
            choices=("default", "sensor_data")),
    Setting("LIGHT_COLOURS", ["red", "green", "blue", "yellow"], "list",
            "colours a code is made of (case-insensitive); black ends a cycle, anything else is unknown"),
    Setting("LIGHT_STALE_AFTER_S", 3.0, "float", "the light sequence is shown stale after this long without a message",
            0.1, 3600),
    Setting("CODE_TOPIC", "/scan_the_code/code", "topic",
            "where each confirmed code is published: std_msgs/String such as `red,green,blue`, transient local"),
    Setting("CODE_CONFIRM_CYCLES", 1, "int",
            "complete cycles in a row that must agree before a code is confirmed and published", 1, 20),
    Setting("CODE_HISTORY_LENGTH", 10, "int", "completed cycles (codes and invalid ones) kept in the history", 1, 100),
)

_BY_NAME = {PREFIX + s.name: s for s in SETTINGS}


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
    if kind == "list":
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
    if kind == "list":
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise fail("a list of strings")
        return list(value)
    if kind in ("str", "topic"):
        if not isinstance(value, str) or (kind == "str" and not value and setting.default):
            raise fail("a non-empty string")
        if setting.choices and value not in setting.choices:
            raise fail("one of " + ", ".join(setting.choices))
        if kind == "topic" and not _TOPIC_RE.match(value):
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
    return merged
