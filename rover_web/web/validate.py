"""Strict JSON input: finite numbers only, explicit ranges, clear messages. Pure Python."""

from __future__ import annotations

import json
import math
import re
from typing import Any


class InvalidInput(ValueError):
    """Input the client must fix; `code` is the short machine-readable reason."""

    def __init__(self, message: str, code: str = "bad_request"):
        super().__init__(message)
        self.code = code


def _refuse_constant(name: str) -> Any:
    raise InvalidInput(f"{name} is not allowed: numbers must be finite", "non_finite")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):  # 1e400 parses to inf
        raise InvalidInput(f"{text} is out of range: numbers must be finite", "non_finite")
    return value


# One decoder for every call: json.loads with hooks builds a new decoder and scanner each time,
# which a teleop frame would pay for 40 times a second.
_STRICT = json.JSONDecoder(parse_constant=_refuse_constant, parse_float=_finite_float)


def loads_strict(data: bytes | str) -> Any:
    """json.loads that refuses NaN, Infinity and overflowing numbers instead of passing them on."""
    try:
        if not isinstance(data, str):
            data = data.decode(json.detect_encoding(data), "surrogatepass")  # as json.loads does
        return _STRICT.decode(data)
    except InvalidInput:
        raise
    except (ValueError, UnicodeDecodeError) as exc:
        raise InvalidInput(f"body is not valid JSON: {exc}", "bad_json") from None
    except RecursionError:
        raise InvalidInput("body is nested too deeply", "bad_json") from None


_JSON_TYPES = {dict: "an object", list: "an array", str: "a string", bool: "a boolean", type(None): "null",
               int: "a number", float: "a number"}


def json_type(value: Any) -> str:
    """What a decoded JSON value is, in JSON's words (an integer and a float are both a number)."""
    return _JSON_TYPES.get(type(value), type(value).__name__)


def number(obj: dict, key: str, *, low: float | None = None, high: float | None = None,
           default: Any = ..., required: bool = True) -> float:
    """A finite number field within [low, high]; booleans and strings are refused."""
    if key not in obj or obj[key] is None and default is not ...:
        if default is not ...:
            return default
        raise InvalidInput(f"'{key}' is required", "missing_field")
    value = obj[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidInput(f"'{key}' must be a number, got {type(value).__name__}", "bad_type")
    try:
        value = float(value)
    except OverflowError:  # an integer of hundreds of digits: JSON allows it, a float cannot hold it
        raise InvalidInput(f"'{key}' is out of range: an integer too large for a number", "out_of_range") from None
    if not math.isfinite(value):
        raise InvalidInput(f"'{key}' must be finite", "non_finite")
    if low is not None and value < low or high is not None and value > high:
        raise InvalidInput(f"'{key}' must be between {low:g} and {high:g}, got {value:g}", "out_of_range")
    return value


def text(obj: dict, key: str, *, max_len: int = 200, default: Any = ..., choices=None) -> str:
    if key not in obj or obj[key] is None and default is not ...:
        if default is not ...:
            return default
        raise InvalidInput(f"'{key}' is required", "missing_field")
    value = obj[key]
    if not isinstance(value, str):
        raise InvalidInput(f"'{key}' must be a string, got {type(value).__name__}", "bad_type")
    if len(value) > max_len:
        raise InvalidInput(f"'{key}' is longer than {max_len} characters", "too_long")
    if choices is not None and value not in choices:
        raise InvalidInput(f"'{key}' must be one of {', '.join(choices)}; got {value[:40]!r}", "bad_value")
    return value


def only_keys(obj: dict, allowed: set[str]) -> None:
    unknown = sorted(set(obj) - allowed)
    if unknown:
        raise InvalidInput(f"unknown field(s): {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}",
                           "unknown_field")


_TOPIC_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
TOPIC_MAX_LEN = 247  # rmw's limit leaves room for the DDS prefix within 255 characters


def topic_name(value: Any, field: str = "topic") -> str:
    """A ROS topic name, fully qualified ('camera/image' becomes '/camera/image').

    The rules of rmw_validate_full_topic_name: '/'-separated tokens of letters, digits and '_',
    none starting with a digit, no empty token, no trailing '/'. Substitutions ('~', '{node}')
    mean nothing to a browser and are refused.
    """
    if not isinstance(value, str) or not value.strip():
        raise InvalidInput(f"'{field}' is required: a ROS topic name such as /camera/image_raw", "missing_field")
    name = value
    if name != name.strip():
        # Not trimmed: a name with a newline or space at an end is a mistake (or a probe) to refuse.
        raise InvalidInput(f"'{field}' {value.strip()[:80]!r} has spaces or line breaks around it", "bad_topic")
    if len(name) > TOPIC_MAX_LEN:
        raise InvalidInput(f"'{field}' is longer than {TOPIC_MAX_LEN} characters", "bad_topic")
    if not name.startswith("/"):
        name = "/" + name
    tokens = name[1:].split("/")
    for token in tokens:
        if not _TOPIC_TOKEN.match(token):
            shown = value.strip()[:80]
            if token == "":
                why = "has an empty part ('//' or a trailing '/')"
            elif token[0].isdigit():
                why = f"has a part starting with a digit ({token[:20]!r})"
            else:
                why = "may only contain letters, digits, '_' and '/'"
            raise InvalidInput(f"'{field}' {shown!r} is not a valid ROS topic name: it {why}", "bad_topic")
    return name
