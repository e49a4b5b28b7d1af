"""Which field paths of a message type hold numbers, read from the type's own field table."""

from __future__ import annotations

import re

from rover_web.ros.graph import deserializer
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.web.api_messages import explain

from .field import FieldError, Step

NUMERIC = {"float", "double", "long double", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
           "uint64", "boolean", "octet", "byte"}
_SEQUENCE_RE = re.compile(r"sequence<(.+?)(?:,\s*\d+)?>\Z")
_ARRAY_RE = re.compile(r"(.+)\[(\d+)\]\Z")
LISTED_MAX = 400  # numeric paths offered for one type
EXPANDED_ARRAY_MAX = 9  # fixed arrays up to this size are offered element by element

__all__ = ["deserializer", "numeric_kind", "numeric_paths"]


def _element(type_str: str) -> tuple[str, int | None] | None:
    """(element type, fixed size or None) of an array or sequence type string; None for a scalar."""
    if m := _SEQUENCE_RE.match(type_str):
        return m.group(1), None
    if m := _ARRAY_RE.match(type_str):
        return m.group(1), int(m.group(2))
    return None


def _fields(type_str: str) -> dict[str, str] | None:
    """The field table of a nested message type string ('geometry_msgs/Pose'), None for a primitive."""
    if "/" not in type_str:
        return None
    try:
        return message_class(type_str).get_fields_and_field_types()
    except UnknownMessageType:
        return None


def numeric_kind(type_name: str, steps: tuple[Step, ...]) -> str:
    """The primitive type at `steps` of `type_name`; FieldError when missing or not a number."""
    current = type_name
    where = ""
    for step in steps:
        if isinstance(step, int):
            element = _element(current)
            if element is None:
                raise FieldError(explain("%(value)s is not an array, so [%(step)s] does not apply",
                                         value=where or 'the message', step=step), "not_array")
            current, size = element
            if size is not None and step >= size:
                raise FieldError(explain("%(where)s has %(size)s elements; [%(step)s] is beyond it",
                                         where=where, size=size, step=step), "no_such_field")
            where += f"[{step}]"
            continue
        if _element(current) is not None:
            raise FieldError(
                explain("%(where)s is an array: give an index, e.g. %(where)s[0]", where=where), "not_numeric"
            )
        fields = _fields(current)
        if fields is None or step not in fields:
            raise FieldError(explain("%(type_name)s has no field %(value)s",
                                     type_name=type_name, value=(where + '.' if where else '') + step), "no_such_field")
        current = fields[step]
        where = f"{where}.{step}" if where else step
    if _element(current) is not None or current not in NUMERIC:
        raise FieldError(explain("%(where)s of %(type_name)s is %(current)s, not a number",
                                 where=where, type_name=type_name, current=current), "not_numeric")
    return current


def numeric_paths(type_name: str, depth: int = 6) -> list[str]:
    """Field paths of `type_name` that hold numbers, for the plot page to offer."""
    out: list[str] = []

    def walk(type_str: str, prefix: str, depth: int) -> None:
        if len(out) >= LISTED_MAX or depth < 0:
            return
        element = _element(type_str)
        if element is not None:
            inner, size = element
            indices = range(size) if size is not None and size <= EXPANDED_ARRAY_MAX else range(1)
            for i in indices:
                walk(inner, f"{prefix}[{i}]", depth - 1)
            return
        if type_str in NUMERIC:
            out.append(prefix)
            return
        fields = _fields(type_str)
        for name, sub in (fields or {}).items():
            walk(sub, f"{prefix}.{name}" if prefix else name, depth - 1)

    walk(type_name, "", depth)
    return out
