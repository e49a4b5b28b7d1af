"""Message classes looked up by their ROS name ("geometry_msgs/msg/Twist" or "geometry_msgs/Twist")."""

from __future__ import annotations

import importlib
import importlib.util
import re
from functools import lru_cache
from pathlib import Path

from rover_web.web.api_messages import explain

# \Z, not $: "$" also matches before a trailing newline.
_TYPE_RE = re.compile(r"([a-z][a-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)\Z")


class UnknownMessageType(LookupError):
    pass


@lru_cache(maxsize=256)
def message_class(type_name: str) -> type:
    """Import a message class by name; raise UnknownMessageType with the reason otherwise."""
    match = _TYPE_RE.match(type_name) if isinstance(type_name, str) else None
    if not match:
        raise UnknownMessageType(explain("%(type_name)s is not a message type name like std_msgs/msg/String",
                                         type_name=repr(type_name)))
    package, name = match.groups()
    if not is_interface_package(package):
        raise UnknownMessageType(explain("%(package)s is not installed as a ROS interface package",
                                         package=repr(package)))
    try:
        module = importlib.import_module(f"{package}.msg")
    except ImportError:
        raise UnknownMessageType(
            explain("message package %(package)s is not installed", package=repr(package))
        ) from None
    cls = getattr(module, name, None)
    if cls is None or not hasattr(cls, "get_fields_and_field_types"):
        raise UnknownMessageType(
            explain("%(package)s has no message %(name)s", package=package, name=repr(name))
        ) from None
    return cls


@lru_cache(maxsize=256)
def is_interface_package(package: str) -> bool:
    """True for a package built by rosidl (it ships its C type support beside its Python code),
    decided without importing it: a type name from a browser must never run an arbitrary
    module's import-time code (`this`, `antigravity`, anything on sys.path)."""
    spec = importlib.util.find_spec(package)  # a top-level name: found, not imported
    if spec is None or not spec.submodule_search_locations:
        return False
    return any(any(Path(location).glob(f"{package}_s__rosidl_typesupport_c*"))
               for location in spec.submodule_search_locations)


def type_name(cls_or_msg) -> str:
    """The canonical "pkg/msg/Name" of a message class or instance."""
    cls = cls_or_msg if isinstance(cls_or_msg, type) else type(cls_or_msg)
    package = cls.__module__.split(".")[0]
    return f"{package}/msg/{cls.__name__}"


_INTERFACE_RE = re.compile(r"([a-z][a-z0-9_]*)/(msg|srv|action)/([A-Z][A-Za-z0-9]*)\Z")


@lru_cache(maxsize=256)
def interface_class(type_name: str) -> type:
    """A message, service or action class by its full name ("std_srvs/srv/SetBool"), imported
    only from a ROS interface package; UnknownMessageType with the reason otherwise."""
    match = _INTERFACE_RE.match(type_name) if isinstance(type_name, str) else None
    if not match:
        raise UnknownMessageType(explain("%(type_name)s is not an interface type name like std_srvs/srv/Trigger or "
                                         "test_msgs/action/Fibonacci",
                                         type_name=repr(str(type_name)[:80])))
    package, kind, name = match.groups()
    if kind == "msg":
        return message_class(type_name)
    if not is_interface_package(package):
        raise UnknownMessageType(explain("%(package)s is not installed as a ROS interface package",
                                         package=repr(package)))
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ImportError:
        raise UnknownMessageType(explain("%(package)s has no %(kind)s types installed",
                                         package=repr(package), kind=kind)) from None
    cls = getattr(module, name, None)
    marker = "Request" if kind == "srv" else "Goal"
    if cls is None or not hasattr(cls, marker):
        raise UnknownMessageType(explain("%(package)s has no %(kind)s %(name)s",
                                         package=package, kind=kind, name=repr(name))) from None
    return cls
