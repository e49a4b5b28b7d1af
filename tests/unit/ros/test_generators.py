"""Message classes work without ROS's code generator in memory (rover_web/ros/generators.py).
Each case runs in a fresh interpreter: what is imported is process-wide."""

import subprocess
import sys

LEAN = """
import sys
from rover_web.ros.generators import without_generators
assert without_generators()
from nav_msgs.msg import Odometry
Odometry.__class__.__import_type_support__()
assert Odometry.__class__._TYPE_SUPPORT is not None
from rclpy.serialization import serialize_message, deserialize_message
msg = Odometry(); msg.pose.pose.position.x = 1.5
assert deserialize_message(serialize_message(msg), Odometry).pose.pose.position.x == 1.5
print(sorted(m for m in ("lark", "em", "rosidl_parser.parser", "rosidl_pycommon") if m in sys.modules))
"""

AFTER = """
import rosidl_generator_py
from rover_web.ros.generators import without_generators
print(without_generators(), hasattr(rosidl_generator_py, "generate_py"))
"""


def run(code):
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_messages_serialise_and_the_generators_stay_out():
    assert run(LEAN) == "[]"


def test_a_package_already_imported_is_left_as_it_is():
    assert run(AFTER) == "False True"
