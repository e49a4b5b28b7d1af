"""Message types named by users: only ROS interface packages are ever imported."""

import subprocess
import sys

import pytest

from rover_web.config import ROOT
from rover_web.ros.typesupport import UnknownMessageType, is_interface_package, message_class


def test_interface_packages_are_recognised_without_being_imported():
    assert is_interface_package("std_msgs") and is_interface_package("sensor_msgs")
    assert not is_interface_package("this") and not is_interface_package("antigravity")
    assert not is_interface_package("json") and not is_interface_package("rover_web")
    assert not is_interface_package("no_such_package_anywhere")


@pytest.mark.parametrize("name", ["this/msg/X", "json/msg/X", "os/msg/X",
                                  "std_msgs/msg/String\n", "std_msgs/msg/String\nx"])
def test_a_name_outside_ros_interface_packages_is_refused_and_imports_nothing(name):
    # In a fresh interpreter, so that "nothing imported" can be checked for modules this one loaded.
    script = (
        "import sys\n"
        "from rover_web.ros.typesupport import UnknownMessageType, message_class\n"
        f"before = set(sys.modules)\n"
        "try:\n"
        f"    message_class({name!r})\n"
        "    print('IMPORTED')\n"
        "except UnknownMessageType as exc:\n"
        "    print('REFUSED', sorted(set(sys.modules) - before))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert result.stdout.strip() == "REFUSED []", (result.stdout, result.stderr)


def test_real_message_types_still_resolve():
    assert message_class("std_msgs/msg/String").__name__ == "String"
    assert message_class("geometry_msgs/Twist").__name__ == "Twist"
    with pytest.raises(UnknownMessageType):
        message_class("std_msgs/msg/NoSuchType")
