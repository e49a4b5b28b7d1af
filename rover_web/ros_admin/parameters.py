"""A parameter value checked against the node's own descriptor before it is sent. Pure Python.

The node checks again (and may refuse with its reason); checking here first gives the operator a
400 naming what is wrong instead of a round trip, and keeps NaN and infinity off the wire.
"""

from __future__ import annotations

import math
import re
from typing import Any

from rover_web.web.api_messages import Text, explain

INT64 = (-2**63, 2**63 - 1)
SCALARS = ("bool", "integer", "double", "string")
ARRAYS = ("byte_array", "bool_array", "integer_array", "double_array", "string_array")
MAX_ARRAY_ITEMS = 10_000
MAX_STRING = 65_536
# rcl's own names plus '/' (qos_overrides./topic.publisher.depth) and '.'; never spaces or controls.
PARAMETER_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_./]{0,254}\Z")


class ParameterRefused(Exception):
    """A value not to send: `status` is 400 (wrong type, out of range) or 409 (read-only)."""

    def __init__(self, status: int, code: str, message: str):
        super().__init__(message)
        self.status, self.code = status, code


def _bad(message_text: Text, code: str = "bad_type") -> ParameterRefused:
    return ParameterRefused(400, code, message_text)


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def infer_kind(value: Any) -> str:
    """The parameter type a JSON value would be (for dynamically typed parameters)."""
    if isinstance(value, bool):
        return "bool"
    if _is_int(value):
        return "integer"
    if isinstance(value, float):
        return "double"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list) and value:
        first = infer_kind(value[0]) if not isinstance(value[0], list) else None
        if first == "integer" and any(isinstance(v, float) for v in value):
            first = "double"
        if first in SCALARS:
            return f"{first}_array"
    raise _bad(explain("cannot tell the parameter type of this value; send a boolean, number, string or non-empty "
                       "array of one of those"))


def _scalar(kind: str, value: Any, where: str) -> Any:
    if kind == "bool":
        if not isinstance(value, bool):
            raise _bad(explain("%(where)s must be true or false", where=where))
        return value
    if kind == "integer":
        if isinstance(value, float) and value.is_integer() and abs(value) < 2**53:
            value = int(value)
        if not _is_int(value):
            raise _bad(explain("%(where)s must be an integer", where=where))
        if not INT64[0] <= value <= INT64[1]:
            raise _bad(explain("%(where)s is out of the 64-bit integer range", where=where), "out_of_range")
        return value
    if kind == "double":
        if not _is_number(value):
            raise _bad(explain("%(where)s must be a number", where=where))
        try:
            number = float(value)
        except OverflowError:
            raise _bad(explain("%(where)s is too large", where=where), "out_of_range") from None
        if not math.isfinite(number):
            raise _bad(explain("%(where)s must be finite", where=where), "non_finite")
        return number
    if kind == "string":
        if not isinstance(value, str):
            raise _bad(explain("%(where)s must be a string", where=where))
        if len(value) > MAX_STRING or "\x00" in value:
            raise _bad(explain("%(where)s is too long or holds a NUL character", where=where), "bad_value")
        return value
    if kind == "byte":
        if not _is_int(value) or not 0 <= value <= 255:
            raise _bad(explain("%(where)s must be an integer from 0 to 255", where=where))
        return value
    raise _bad(explain("parameters of type %(kind)s cannot be set from here", kind=kind))


def check_value(param: dict, value: Any) -> tuple[str, Any]:
    """(type, value to send) for setting `param` (as AdminNode.parameters lists it) to `value`."""
    name = param["name"]
    if param.get("read_only"):
        raise ParameterRefused(409, "read_only", explain("%(name)s is read-only: it can only be set when the node "
                                                         "starts",
                                                         name=name))
    kind = param["type"]
    if param.get("dynamic_typing") or kind == "not_set":
        kind = infer_kind(value)
    if kind in ARRAYS:
        if not isinstance(value, list):
            raise _bad(explain("%(name)s is a %(kind)s: send an array", name=name, kind=kind))
        if len(value) > MAX_ARRAY_ITEMS:
            raise _bad(explain("%(name)s: at most %(max_array_items)s items",
                               name=name, max_array_items=MAX_ARRAY_ITEMS), "too_long")
        item = kind[:-len("_array")]
        return kind, [_scalar(item, v, f"{name}[{i}]") for i, v in enumerate(value)]
    value = _scalar(kind, value, name)
    _check_range(name, param.get("range"), value)
    return kind, value


def _check_range(name: str, bounds: dict | None, value: Any) -> None:
    if not bounds or isinstance(value, (bool, str)):
        return
    low, high, step = bounds["from"], bounds["to"], bounds["step"]
    if bounds["kind"] == "integer":
        inside = low <= value <= high
        on_step = not step or value == high or (value - low) % step == 0
    else:
        tolerance = 1e-6 * max(1.0, abs(high), abs(low))  # as rclpy compares doubles
        inside = low - tolerance <= value <= high + tolerance
        on_step = True
        if step:
            steps = (value - low) / step
            on_step = abs(value - high) <= tolerance or abs(steps - round(steps)) * step <= tolerance
    if not inside:
        raise _bad(
            explain(
                "%(name)s must be between %(low)s and %(high)s, got %(value)s",
                name=name,
                low=format(low, "g"),
                high=format(high, "g"),
                value=format(value, "g"),
            ),
            "out_of_range",
        )
    if not on_step:
        raise _bad(
            explain(
                "%(name)s must be %(low)s plus a multiple of %(step)s, got %(value)s",
                name=name,
                low=format(low, "g"),
                step=format(step, "g"),
                value=format(value, "g"),
            ),
            "out_of_range",
        )
