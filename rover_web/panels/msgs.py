"""Messages for control panels: std_msgs scalar commands out, one field of any message in."""

from __future__ import annotations

import array
import math
from typing import Any

from rover_web.ros.convert import message_to_dict
from rover_web.ros.typesupport import message_class

_INT_FIELDS = {"octet", "byte", "char", "uint8", "int8", "uint16", "int16", "uint32", "int32", "uint64", "int64"}
_FLOAT_FIELDS = {"float", "double", "long double"}


def scalar_message(type_name: str, value: Any):
    """A fresh std_msgs/<Scalar> or String with `data` = value (already checked by the panel spec).

    rclpy does not range-check fields (its checks are off by default), so an Int8 of 200 would go
    out wrapped; callers validate first (rover_web.panels.scalars.coerce).
    """
    msg = message_class(type_name)()
    field_type = msg.get_fields_and_field_types()["data"]
    if field_type == "octet":
        msg.data = bytes([value])
    elif field_type in _FLOAT_FIELDS:
        msg.data = float(value)
    else:
        msg.data = value
    return msg


def field_kind(type_name: str, path: str) -> str:
    """What `path` holds in `type_name`: string, int, float, bool, message or other (arrays).

    LookupError when the type does not exist, ValueError naming the missing field otherwise.
    """
    cls = message_class(type_name)
    if not path:
        return "message"
    walked = []
    for part in path.split("."):
        fields = cls.get_fields_and_field_types() if cls is not None else {}
        if part not in fields:
            where = type_name + (" " + ".".join(walked) if walked else "")
            raise ValueError(f"{where} has no field {part!r}; it has {', '.join(fields) or 'no fields'}")
        walked.append(part)
        field_type = fields[part]
        cls = None
        if "/" in field_type and not field_type.startswith("sequence<") and "[" not in field_type:
            cls = message_class(field_type)
    if cls is not None:
        return "message"
    if field_type.startswith(("string", "wstring")):
        return "string"
    if field_type in _INT_FIELDS:
        return "int"
    if field_type in _FLOAT_FIELDS:
        return "float"
    if field_type == "boolean":
        return "bool"
    return "other"


def read_field(msg: Any, path: str, max_items: int = 16) -> Any:
    """The JSON-ready value at `path` ("" is the whole message); NaN and infinities become text."""
    value = msg
    if path:
        for part in path.split("."):
            value = getattr(value, part)
    return _plain(value, max_items)


def _plain(value: Any, max_items: int) -> Any:
    if hasattr(value, "get_fields_and_field_types"):
        return message_to_dict(value, max_items)
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, (bytes, bytearray)):
        return value[0] if len(value) == 1 else list(value[:max_items])
    if isinstance(value, array.array) or type(value).__module__ == "numpy":
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v, max_items) for v in value[:max_items]]
    return value
