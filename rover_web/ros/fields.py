"""JSON values checked field by field against a ROS type, and a type's fields described for forms.

Everything a browser sends to a service or an action is checked here before any message is built:
unknown fields, wrong JSON types, integers out of their type's range, floats that are not finite
(NaN and infinity never reach a message), strings and sequences over their bound, fixed arrays of
the wrong length. An error names the field's path (`goal.pose.position.x`, `data[2]`).
"""

from __future__ import annotations

import math
from typing import Any

from rosidl_parser.definition import (
    AbstractGenericString,
    AbstractSequence,
    Array,
    BasicType,
    BoundedSequence,
    NamespacedType,
)

from rover_web.web.api_messages import explain

from .typesupport import message_class

INT_RANGES = {
    "int8": (-2**7, 2**7 - 1), "uint8": (0, 2**8 - 1), "char": (0, 2**8 - 1), "octet": (0, 2**8 - 1),
    "int16": (-2**15, 2**15 - 1), "uint16": (0, 2**16 - 1),
    "int32": (-2**31, 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-2**63, 2**63 - 1), "uint64": (0, 2**64 - 1),
}
FLOATS = {"float", "double", "long double"}
FLOAT32_MAX = 3.4028234663852886e38
MAX_DEPTH = 16


class FieldError(ValueError):
    """A value that does not fit its field; `path` names the field, `code` the short reason."""

    def __init__(self, path: str, message: str, code: str = "bad_field"):
        super().__init__(explain("%(path)s: %(why)s", path=path, why=message) if path
                         else explain("the value: %(why)s", why=message))
        self.path, self.code = path, code


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _nested_class(slot: NamespacedType) -> type:
    return message_class(f"{slot.namespaces[0]}/msg/{slot.name}")


def _type_word(value: Any) -> str:
    return {bool: "a boolean", int: "an integer", float: "a number", str: "a string", list: "an array",
            dict: "an object", type(None): "null"}.get(type(value), type(value).__name__)


def build(cls: type, data: Any, path: str = "", depth: int = 0) -> Any:
    """A message of `cls` from a JSON object; FieldError if any field does not fit. Missing fields
    keep their defaults."""
    if depth > MAX_DEPTH:
        raise FieldError(path, explain("nested too deeply"), "too_deep")
    if not isinstance(data, dict):
        raise FieldError(path, explain("must be an object, got %(type_word)s", type_word=_type_word(data)), "bad_type")
    fields = cls.get_fields_and_field_types()
    unknown = [k for k in data if k not in fields]
    if unknown:
        name = str(unknown[0])[:60]
        raise FieldError(
            _join(path, name),
            explain(
                "%(name)s has no such field; its fields: %(value)s",
                name=cls.__name__,
                value=", ".join(fields) or "(none)",
            ),
            "unknown_field",
        )
    msg = cls()
    for (name, _), slot in zip(fields.items(), cls.SLOT_TYPES, strict=True):
        if name in data:
            setattr(msg, name, _value(slot, data[name], _join(path, name), depth + 1))
    return msg


def _value(slot: Any, value: Any, path: str, depth: int) -> Any:
    if isinstance(slot, BasicType):
        return _basic(slot.typename, value, path)
    if isinstance(slot, AbstractGenericString):
        if not isinstance(value, str):
            raise FieldError(
                path, explain("must be a string, got %(type_word)s", type_word=_type_word(value)), "bad_type"
            )
        limit = getattr(slot, "maximum_size", None)
        if limit is not None and len(value) > limit:
            raise FieldError(path, explain("is longer than its bound of %(limit)s characters", limit=limit), "too_long")
        if "\x00" in value:
            raise FieldError(path, explain("may not contain a NUL character"), "bad_value")
        return value
    if isinstance(slot, NamespacedType):
        return build(_nested_class(slot), value, path, depth)
    if isinstance(slot, (Array, AbstractSequence)):
        if not isinstance(value, list):
            raise FieldError(
                path, explain("must be an array, got %(type_word)s", type_word=_type_word(value)), "bad_type"
            )
        if isinstance(slot, Array) and len(value) != slot.size:
            raise FieldError(path, explain("must have exactly %(size)s items, got %(count)s",
                                           size=slot.size, count=len(value)), "bad_length")
        if isinstance(slot, BoundedSequence) and len(value) > slot.maximum_size:
            raise FieldError(path, explain("may have at most %(maximum_size)s items, got %(count)s",
                                           maximum_size=slot.maximum_size, count=len(value)), "too_long")
        items = [_value(slot.value_type, item, f"{path}[{i}]", depth) for i, item in enumerate(value)]
        return items
    raise FieldError(
        path, explain("has a type this browser cannot fill (%(type)s)", type=type(slot).__name__), "unsupported"
    )


def _basic(typename: str, value: Any, path: str) -> Any:
    if typename == "boolean":
        if not isinstance(value, bool):
            raise FieldError(
                path, explain("must be true or false, got %(type_word)s", type_word=_type_word(value)), "bad_type"
            )
        return value
    if typename in FLOATS:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise FieldError(
                path, explain("must be a number, got %(type_word)s", type_word=_type_word(value)), "bad_type"
            )
        try:
            number = float(value)
        except OverflowError:
            raise FieldError(path, explain("is too large for a number"), "out_of_range") from None
        if not math.isfinite(number):
            raise FieldError(path, explain("must be finite"), "non_finite")
        if typename == "float" and abs(number) > FLOAT32_MAX:
            raise FieldError(path, explain("is out of range for a 32-bit float"), "out_of_range")
        return number
    low, high = INT_RANGES[typename]
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)  # JSON from a browser writes 3 as 3.0 sometimes
        else:
            raise FieldError(
                path, explain("must be an integer, got %(type_word)s", type_word=_type_word(value)), "bad_type"
            )
    if not low <= value <= high:
        raise FieldError(path, explain("must be between %(low)s and %(high)s (%(typename)s)",
                                       low=low, high=high, typename=typename), "out_of_range")
    return bytes([value]) if typename == "octet" else value


def describe(cls: type, depth: int = 0) -> list[dict]:
    """The fields of a message class for a generated form: name, type text and kind, bounds,
    nested fields."""
    out = []
    for (name, text), slot in zip(cls.get_fields_and_field_types().items(), cls.SLOT_TYPES, strict=True):
        out.append({"name": name, "type": text, **_describe_slot(slot, depth)})
    return out


def _describe_slot(slot: Any, depth: int) -> dict:
    if isinstance(slot, BasicType):
        if slot.typename == "boolean":
            return {"kind": "bool"}
        if slot.typename in FLOATS:
            return {"kind": "float"}
        low, high = INT_RANGES[slot.typename]
        return {"kind": "int", "min": low, "max": high}
    if isinstance(slot, AbstractGenericString):
        return {"kind": "string", "max_length": getattr(slot, "maximum_size", None)}
    if isinstance(slot, NamespacedType):
        nested = describe(_nested_class(slot), depth + 1) if depth < MAX_DEPTH else []
        return {"kind": "message", "fields": nested}
    if isinstance(slot, (Array, AbstractSequence)):
        item = _describe_slot(slot.value_type, depth)
        size = {"size": slot.size} if isinstance(slot, Array) else {
            "max_items": getattr(slot, "maximum_size", None)}
        return {"kind": "array", **size, "item": item}
    return {"kind": "unsupported"}
