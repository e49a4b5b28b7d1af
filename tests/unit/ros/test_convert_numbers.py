"""A JSON int given for a float field reaches the wire as that number (rclpy, with its field checks off,
had kept the int and its C side read the object as a double: 4 went out as 2e-323, -1 as NaN)."""

from rclpy.serialization import deserialize_message, serialize_message

from rover_web.ros.convert import dict_to_message
from rover_web.ros.typesupport import message_class


def test_ints_in_float_fields_survive_serialisation():
    msg = dict_to_message("visualization_msgs/msg/Marker", {"pose": {"position": {"x": 4, "y": -1, "z": 0}},
                                                            "scale": {"x": 2}, "color": {"r": 1, "a": 1}, "id": 3})
    back = deserialize_message(serialize_message(msg), message_class("visualization_msgs/msg/Marker"))
    assert (back.pose.position.x, back.pose.position.y, back.scale.x) == (4.0, -1.0, 2.0)
    assert (back.color.r, back.color.a, back.id) == (1.0, 1.0, 3)
