"""The std_msgs scalar types a panel control publishes, and the values each one accepts.

A control's value comes from the panel file (a button's fixed value, an input's range) or from the
operator at run time; both go through `coerce`, so a value is refused the same way wherever it
comes from. `canonical_type` is the one spelling of a message type name the panels use.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from rover_web.web.api_messages import explain

MAX_STRING_LENGTH = 1024

FLOAT32_MAX = 3.4028234663852886e38
FLOAT64_MAX = 1.7976931348623157e308


@dataclass(frozen=True)
class ScalarType:
    """A std_msgs message with one `data` field: what JSON values it takes and their range."""

    name: str  # canonical, "std_msgs/msg/Int8"
    kind: str  # int | float | bool | string
    low: float | None = None
    high: float | None = None

    @property
    def short(self) -> str:
        return self.name.replace("/msg/", "/")


def _int(name: str, bits: int, signed: bool) -> ScalarType:
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return ScalarType(f"std_msgs/msg/{name}", "int", low, high)


SCALAR_TYPES: dict[str, ScalarType] = {t.name: t for t in (
    ScalarType("std_msgs/msg/Bool", "bool"),
    _int("Byte", 8, False),   # octet: one byte, sent as 0..255
    _int("Char", 8, False),   # ROS 2 char is an unsigned 8-bit integer
    _int("Int8", 8, True), _int("UInt8", 8, False),
    _int("Int16", 16, True), _int("UInt16", 16, False),
    _int("Int32", 32, True), _int("UInt32", 32, False),
    _int("Int64", 64, True), _int("UInt64", 64, False),
    ScalarType("std_msgs/msg/Float32", "float", -FLOAT32_MAX, FLOAT32_MAX),
    ScalarType("std_msgs/msg/Float64", "float", -FLOAT64_MAX, FLOAT64_MAX),
    ScalarType("std_msgs/msg/String", "string"),
)}

_TYPE_NAME_RE = re.compile(r"([a-z][a-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)\Z")


def canonical_type(name: str) -> str | None:
    """"std_msgs/Int8" and "std_msgs/msg/Int8" both become "std_msgs/msg/Int8"; None if malformed."""
    match = _TYPE_NAME_RE.match(name) if isinstance(name, str) else None
    return f"{match.group(1)}/msg/{match.group(2)}" if match else None


class InvalidValue(ValueError):
    """A value a control cannot publish; `code` is the API's short reason."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


def coerce(stype: ScalarType, value: Any, *, low: float | None = None, high: float | None = None,
           max_length: int = MAX_STRING_LENGTH) -> Any:
    """The value as the message field wants it, or InvalidValue saying why it cannot be sent."""
    low = stype.low if low is None else low
    high = stype.high if high is None else high
    if stype.kind == "bool":
        if not isinstance(value, bool):
            raise InvalidValue(explain("must be true or false for %(short)s, got %(describe)s",
                                       short=stype.short, describe=describe(value)), "bad_type")
        return value
    if stype.kind == "string":
        if not isinstance(value, str):
            raise InvalidValue(explain("must be a string for %(short)s, got %(describe)s",
                                       short=stype.short, describe=describe(value)), "bad_type")
        if len(value) > max_length:
            raise InvalidValue(explain("must be at most %(max_length)s characters, got %(count)s",
                                       max_length=max_length, count=len(value)), "too_long")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        expected = "an integer" if stype.kind == "int" else "a number"
        raise InvalidValue(explain("must be %(expected)s for %(short)s, got %(describe)s",
                                   expected=expected, short=stype.short, describe=describe(value)), "bad_type")
    if isinstance(value, float) and not math.isfinite(value):
        raise InvalidValue(explain("must be a finite number, got %(value)s", value=value), "non_finite")
    if stype.kind == "int":
        if isinstance(value, float):
            if not value.is_integer():
                raise InvalidValue(explain("must be an integer for %(short)s, got %(value)s",
                                           short=stype.short, value=format(value, "g")), "bad_type")
            value = int(value)
    if value < low or value > high:  # before float(): an integer of hundreds of digits overflows it
        huge = isinstance(value, int) and abs(value) >= 10 ** 30
        shown = f"an integer of {len(str(abs(value)))} digits" if huge else number_text(value)
        raise InvalidValue(
            explain(
                "must be from %(number_text)s to %(number_text2)s for %(short)s, got %(shown)s",
                number_text=number_text(low),
                number_text2=number_text(high),
                short=stype.short,
                shown=shown,
            ),
            "out_of_range",
        )
    return value if stype.kind == "int" else float(value)


def number_text(value: float) -> str:
    return str(value) if isinstance(value, int) else f"{value:g}"


def describe(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"the string {value[:40]!r}"
    if isinstance(value, (int, float)):
        return number_text(value)
    if value == []:
        return "an empty list"
    return {dict: "an object", list: "a list", type(None): "null"}.get(type(value), type(value).__name__)
