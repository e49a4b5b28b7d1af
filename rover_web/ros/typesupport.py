"""Message classes looked up by their ROS name ("geometry_msgs/msg/Twist" or "geometry_msgs/Twist")."""

from __future__ import annotations

import importlib
import re
from functools import lru_cache

_TYPE_RE = re.compile(r"^([a-z][a-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)$")


class UnknownMessageType(LookupError):
    pass


@lru_cache(maxsize=256)
def message_class(type_name: str) -> type:
    """Import a message class by name; raise UnknownMessageType with the reason otherwise."""
    match = _TYPE_RE.match(type_name or "")
    if not match:
        raise UnknownMessageType(f"{type_name!r} is not a message type name like std_msgs/msg/String")
    package, name = match.groups()
    try:
        module = importlib.import_module(f"{package}.msg")
    except ImportError:
        raise UnknownMessageType(f"message package {package!r} is not installed") from None
    cls = getattr(module, name, None)
    if cls is None or not hasattr(cls, "get_fields_and_field_types"):
        raise UnknownMessageType(f"{package} has no message {name!r}") from None
    return cls


def type_name(cls_or_msg) -> str:
    """The canonical "pkg/msg/Name" of a message class or instance."""
    cls = cls_or_msg if isinstance(cls_or_msg, type) else type(cls_or_msg)
    package = cls.__module__.split(".")[0]
    return f"{package}/msg/{cls.__name__}"
