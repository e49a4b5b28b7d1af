"""The ros2msg schema of a message type: the text `ros2 bag record` writes into an MCAP file.

rosbag2's LocalMessageDefinitionSource (rosbag2_cpp) reads the .msg file a rosidl package installs
in <prefix>/share/<pkg>/msg/<Type>.msg and appends, depth first, each type it uses once (in the
sorted order of its std::set), each after "\n", a line of 80 '=' and `MSG: <name as written>`.
This module does the same, so a recording's schemas are those of `ros2 bag record`: readers
(Foxglove, Lichtblick, mcap-ros2-support, rosbags) parse that text to decode the CDR. One
deliberate difference: `wstring` counts as a primitive here (rosbag2 takes it for a type of the
package, finds no .msg and falls back to IDL).
"""

from __future__ import annotations

import os
import re
import sys
from functools import lru_cache
from pathlib import Path

from rover_web.web.api_messages import explain

SEPARATOR = "=" * 80
PRIMITIVES = frozenset({"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
                        "int32", "uint32", "int64", "uint64", "string", "wstring"})
_TYPE_NAME = re.compile(r"([a-z][a-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)\Z")


class SchemaNotFound(LookupError):
    """The .msg file of a type (or of a type it uses) is not installed."""


def _prefixes() -> list[Path]:
    # AMENT_PREFIX_PATH is how a sourced ROS install says where it is; a virtualenv that holds the
    # ROS packages (this project's) has them under its own prefix.
    found = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [*found, Path(sys.prefix)]


@lru_cache(maxsize=512)
def _msg_file(package: str, name: str) -> str:
    for prefix in _prefixes():
        path = prefix / "share" / package / "msg" / f"{name}.msg"
        if path.is_file():
            return path.read_text(encoding="utf-8")
    raise SchemaNotFound(explain("%(package)s/msg/%(name)s.msg is not installed (looked under AMENT_PREFIX_PATH "
                                 "and %(prefix)s)",
                                 package=package, name=name, prefix=sys.prefix))


# rosbag2's own pattern for a field's type at the start of a line ("foo_msgs/Bar" in "foo_msgs/Bar[] bar"):
# comments, bounded strings and constants of primitive types never name a dependency.
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")


def _dependencies(package: str, text: str) -> list[str]:
    """The types a .msg text uses, as rosbag2 names them ("std_msgs/Header" as written, or
    "<package>/Type" for a type of the same package), sorted as its std::set keeps them."""
    found = set()
    for match in _FIELD_TYPE.finditer(text):
        name = match.group(1)
        if name in PRIMITIVES:
            continue
        found.add(name if "/" in name else f"{package}/{name}")
    return sorted(found)


@lru_cache(maxsize=256)
def schema_text(type_name: str) -> str:
    """The full ros2msg definition of "pkg/msg/Type" (or "pkg/Type"); SchemaNotFound if missing."""
    match = _TYPE_NAME.match(type_name)
    if match is None:
        raise SchemaNotFound(explain("%(type_name)s is not a message type name like std_msgs/msg/String",
                                     type_name=repr(type_name)))
    package, name = match.groups()
    seen: set[str] = set()

    def full_text(pkg: str, type_name: str) -> str:
        text = _msg_file(pkg, type_name)
        for dep in _dependencies(pkg, text):
            if dep not in seen:  # depth first, each type once in the whole text
                seen.add(dep)
                dep_pkg, _, dep_name = dep.partition("/")
                text += f"\n{SEPARATOR}\nMSG: {dep}\n" + full_text(dep_pkg, dep_name.rpartition("/")[2])
        return text

    return full_text(package, name)
