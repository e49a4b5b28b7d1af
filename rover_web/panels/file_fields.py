"""Reading one field of a panel file's table, with errors that name where it is.

Each reader checks a field's type and range and raises a ConfigError reading
"<file>: panel 'p', control 'c', field 'f': <what is wrong>" (see Where), so rover_web.panels.spec
reads like the panel file it validates.
"""

from __future__ import annotations

import math
import re
from typing import Any

from rover_web.config import TOPIC_PATTERN, ConfigError

from .scalars import InvalidValue, ScalarType, canonical_type, coerce, describe

ID_RE = re.compile(r"[a-z][a-z0-9_-]{0,31}\Z")


class Where:
    """Builds error messages that name the file, panel, item and field."""

    def __init__(self, path: str, panel: str | None = None, item: str | None = None):
        self.path, self.panel, self.item = path, panel, item

    def at(self, item: str) -> Where:
        return Where(self.path, self.panel, item)

    def error(self, problem: str, field: str | None = None) -> ConfigError:
        parts = []
        if self.panel is not None:
            parts.append(f"panel '{self.panel}'")
        if self.item is not None:
            parts.append(self.item)
        if field is not None:
            parts.append(f"field '{field}'")
        where = ", ".join(parts)
        return ConfigError(f"{self.path}: {where + ': ' if where else ''}{problem}")


def only_keys(table: dict, allowed: set[str], where: Where, what: str | None) -> None:
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise where.error(f"unknown field{'s' if len(unknown) > 1 else ''} {', '.join(repr(k) for k in unknown)}"
                          f"{' in ' + what if what else ''}; expected {', '.join(sorted(allowed))}")


def check_id(item_id: str, where: Where) -> None:
    if not ID_RE.match(item_id):
        raise where.error("ids are 1-32 lower-case letters, digits, '-' or '_', starting with a letter")


def sub_tables(table: dict, key: str, where: Where) -> dict:
    value = table.get(key, {})
    if not isinstance(value, dict):
        raise where.error(f"must be tables such as [panels.{where.panel}.{key}.<id>], got {describe(value)}", key)
    return value


def text_field(table: dict, key: str, where: Where, default: Any = ..., allow_empty: bool = False) -> str:
    if key not in table:
        if default is ...:
            raise where.error("is required", key)
        return default
    value = table[key]
    if not isinstance(value, str) or (not value.strip() and not allow_empty):
        raise where.error(f"must be a non-empty string, got {describe(value)}", key)
    if len(value) > 200:
        raise where.error("is longer than 200 characters", key)
    return value


def topic_field(table: dict, where: Where) -> str:
    topic = text_field(table, "topic", where)
    if not TOPIC_PATTERN.match(topic):
        raise where.error(f"{topic!r} is not a ROS topic name such as /control_phase", "topic")
    return topic if topic.startswith(("/", "~")) else "/" + topic


def type_field(table: dict, where: Where) -> str:
    raw = text_field(table, "type", where)
    name = canonical_type(raw)
    if name is None:
        raise where.error(f"{raw!r} is not a message type such as std_msgs/msg/Int8", "type")
    return name


def positive_field(table: dict, key: str, where: Where, default: float) -> float:
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise where.error(f"must be a positive number of seconds, got {describe(value)}", key)
    return float(value)


def bool_field(table: dict, key: str, where: Where, default: bool) -> bool:
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise where.error(f"must be true or false, got {describe(value)}", key)
    return value


def bound_field(table: dict, key: str, stype: ScalarType, where: Where, default: float) -> float:
    if key not in table:
        return default
    try:
        return coerce(stype, table[key])
    except InvalidValue as exc:
        raise where.error(str(exc), key) from None
