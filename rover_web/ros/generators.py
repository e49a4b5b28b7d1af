"""Message classes without ROS's code generator in memory.

Every generated message class (Jazzy) finds its C type support with
`from rosidl_generator_py import import_type_support`, and that package's __init__ also imports
its code generator: rosidl_parser's Lark grammar and empy, about 8 MB of a server that never
generates code (RSS of rclpy and one message: 43 MB with them, 35 MB without). Registering the
package with only its import_type_support submodule, before any message is imported, keeps them
out. If that submodule cannot be found (another ROS layout), nothing is changed.
"""

from __future__ import annotations

import importlib.util
import sys
import types

PACKAGE = "rosidl_generator_py"


def without_generators() -> bool:
    """Register the lean package; False if it was imported already or cannot be made lean."""
    if PACKAGE in sys.modules:
        return False
    spec = importlib.util.find_spec(PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        return False
    package = types.ModuleType(PACKAGE)
    package.__spec__, package.__file__ = spec, spec.origin
    package.__path__ = list(spec.submodule_search_locations)
    sys.modules[PACKAGE] = package
    try:
        from rosidl_generator_py.import_type_support_impl import import_type_support
    except ImportError:
        del sys.modules[PACKAGE]  # the real package, generators and all, is imported when needed
        return False
    package.import_type_support = import_type_support
    package.__all__ = ["import_type_support"]
    return True
