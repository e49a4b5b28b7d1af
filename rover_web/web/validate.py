"""Strict JSON input: finite numbers only, explicit ranges, clear messages. Pure Python."""

from __future__ import annotations

import json
import math
import re
from typing import Any

from .api_messages import Text, as_text, explain


class InvalidInput(ValueError):
    """Input the client must fix; `code` is the short machine-readable reason.

    `message` is an English msgid with `%(name)s` placeholders filled from `values` (api_messages.py):
    English in str(exc), translated in the answer (`ApiError(400, exc.code, exc.text)`).
    """

    def __init__(self, message: str | Text, code: str = "bad_request", **values: Any):
        self.text = as_text(message, values)
        super().__init__(self.text.english())
        self.code = code


def _refuse_constant(name: str) -> Any:
    raise InvalidInput("%(name)s is not allowed: numbers must be finite", "non_finite", name=name)


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):  # 1e400 parses to inf
        raise InvalidInput("%(number)s is out of range: numbers must be finite", "non_finite", number=text)
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
        raise InvalidInput("body is not valid JSON: %(why)s", "bad_json", why=str(exc)) from None
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
        raise InvalidInput("'%(key)s' is required", "missing_field", key=key)
    value = obj[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidInput("'%(key)s' must be a number, got %(type)s", "bad_type", key=key, type=type(value).__name__)
    try:
        value = float(value)
    except OverflowError:  # an integer of hundreds of digits: JSON allows it, a float cannot hold it
        raise InvalidInput("'%(key)s' is out of range: an integer too large for a number", "out_of_range",
                           key=key) from None
    if not math.isfinite(value):
        raise InvalidInput("'%(key)s' must be finite", "non_finite", key=key)
    if low is not None and value < low or high is not None and value > high:
        raise InvalidInput("'%(key)s' must be between %(low)s and %(high)s, got %(value)s", "out_of_range",
                           key=key, low=format(low, "g"), high=format(high, "g"), value=format(value, "g"))
    return value


def text(obj: dict, key: str, *, max_len: int = 200, default: Any = ..., choices=None) -> str:
    if key not in obj or obj[key] is None and default is not ...:
        if default is not ...:
            return default
        raise InvalidInput("'%(key)s' is required", "missing_field", key=key)
    value = obj[key]
    if not isinstance(value, str):
        raise InvalidInput("'%(key)s' must be a string, got %(type)s", "bad_type", key=key, type=type(value).__name__)
    if len(value) > max_len:
        raise InvalidInput("'%(key)s' is longer than %(max_len)s characters", "too_long", key=key, max_len=max_len)
    if choices is not None and value not in choices:
        raise InvalidInput("'%(key)s' must be one of %(choices)s; got %(value)s", "bad_value",
                           key=key, choices=", ".join(choices), value=repr(value[:40]))
    return value


def only_keys(obj: dict, allowed: set[str]) -> None:
    unknown = sorted(set(obj) - allowed)
    if unknown:
        raise InvalidInput("unknown field(s): %(unknown)s; allowed: %(allowed)s", "unknown_field",
                           unknown=", ".join(unknown), allowed=", ".join(sorted(allowed)))


_TOPIC_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
TOPIC_MAX_LEN = 247  # rmw's limit leaves room for the DDS prefix within 255 characters


def topic_name(value: Any, field: str = "topic") -> str:
    """A ROS topic name, fully qualified ('camera/image' becomes '/camera/image').

    The rules of rmw_validate_full_topic_name: '/'-separated tokens of letters, digits and '_',
    none starting with a digit, no empty token, no trailing '/'. Substitutions ('~', '{node}')
    mean nothing to a browser and are refused.
    """
    if not isinstance(value, str) or not value.strip():
        raise InvalidInput("'%(field)s' is required: a ROS topic name such as /camera/image_raw", "missing_field",
                           field=field)
    name = value
    if name != name.strip():
        # Not trimmed: a name with a newline or space at an end is a mistake (or a probe) to refuse.
        raise InvalidInput("'%(field)s' %(value)s has spaces or line breaks around it", "bad_topic",
                           field=field, value=repr(value.strip()[:80]))
    if len(name) > TOPIC_MAX_LEN:
        raise InvalidInput("'%(field)s' is longer than %(max_len)s characters", "bad_topic",
                           field=field, max_len=TOPIC_MAX_LEN)
    if not name.startswith("/"):
        name = "/" + name
    tokens = name[1:].split("/")
    for token in tokens:
        if not _TOPIC_TOKEN.match(token):
            shown = value.strip()[:80]
            if token == "":
                why = explain("has an empty part ('//' or a trailing '/')")
            elif token[0].isdigit():
                why = explain("has a part starting with a digit (%(part)s)", part=repr(token[:20]))
            else:
                why = explain("may only contain letters, digits, '_' and '/'")
            raise InvalidInput("'%(field)s' %(name)s is not a valid ROS topic name: it %(why)s", "bad_topic",
                               field=field, name=repr(shown), why=why)
    return name
