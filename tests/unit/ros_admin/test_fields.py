"""JSON checked against ROS types field by field: every refusal names the field path."""

import math

import pytest

from rover_web.ros.fields import FieldError, build, describe
from rover_web.ros.typesupport import UnknownMessageType, interface_class, message_class

BASIC = message_class("test_msgs/msg/BasicTypes")
ARRAYS = message_class("test_msgs/msg/Arrays")
BOUNDED = message_class("test_msgs/msg/BoundedSequences")
STRINGS = message_class("test_msgs/msg/Strings")
POSE = message_class("geometry_msgs/msg/PoseStamped")


def refused(cls, data):
    with pytest.raises(FieldError) as caught:
        build(cls, data)
    return caught.value.path, caught.value.code


def test_every_basic_type_is_built():
    msg = build(BASIC, {"bool_value": True, "byte_value": 255, "char_value": 65, "float32_value": 1.5,
                        "float64_value": -2, "int8_value": -128, "uint8_value": 255, "int16_value": -32768,
                        "uint16_value": 65535, "int32_value": -2**31, "uint32_value": 2**32 - 1,
                        "int64_value": -2**63, "uint64_value": 2**64 - 1})
    assert (msg.bool_value, msg.byte_value, msg.float64_value, msg.uint64_value) == (True, b"\xff", -2.0, 2**64 - 1)


@pytest.mark.parametrize("field,value,code", [
    ("int8_value", 128, "out_of_range"), ("int8_value", -129, "out_of_range"), ("uint8_value", -1, "out_of_range"),
    ("uint64_value", 2**64, "out_of_range"), ("int64_value", 2**63, "out_of_range"),
    ("byte_value", 256, "out_of_range"),
    ("int32_value", 1.5, "bad_type"), ("int32_value", True, "bad_type"), ("int32_value", "1", "bad_type"),
    ("bool_value", 1, "bad_type"), ("bool_value", None, "bad_type"),
    ("float64_value", math.nan, "non_finite"), ("float64_value", math.inf, "non_finite"),
    ("float32_value", 1e39, "out_of_range"), ("float64_value", "1.0", "bad_type"), ("float64_value", False, "bad_type"),
    ("float64_value", 10**400, "out_of_range"),
])
def test_basic_values_that_do_not_fit(field, value, code):
    assert refused(BASIC, {field: value}) == (field, code)


def test_integral_floats_are_integers():
    assert build(BASIC, {"int32_value": 3.0}).int32_value == 3


def test_unknown_fields_and_non_objects():
    assert refused(BASIC, {"nope": 1}) == ("nope", "unknown_field")
    assert refused(BASIC, [1]) == ("", "bad_type")
    assert refused(POSE, {"pose": {"position": {"x": 1.0, "w": 2}}}) == ("pose.position.w", "unknown_field")


def test_nested_messages_name_the_whole_path():
    msg = build(POSE, {"header": {"frame_id": "map", "stamp": {"sec": 5}}, "pose": {"position": {"x": 1.5}}})
    assert (msg.header.frame_id, msg.header.stamp.sec, msg.pose.position.x) == ("map", 5, 1.5)
    assert refused(POSE, {"pose": {"position": {"x": math.nan}}}) == ("pose.position.x", "non_finite")
    assert refused(POSE, {"header": {"stamp": {"sec": 2**31}}}) == ("header.stamp.sec", "out_of_range")
    assert refused(POSE, {"pose": 3}) == ("pose", "bad_type")


def test_fixed_arrays_need_their_exact_length():
    msg = build(ARRAYS, {"int32_values": [1, 2, 3], "byte_values": [0, 1, 2],
                         "basic_types_values": [{"int8_value": 1}, {}, {}]})
    assert list(msg.int32_values) == [1, 2, 3] and msg.basic_types_values[0].int8_value == 1
    assert refused(ARRAYS, {"int32_values": [1, 2]}) == ("int32_values", "bad_length")
    assert refused(ARRAYS, {"int32_values": [1, 2, 2**31]}) == ("int32_values[2]", "out_of_range")
    assert refused(ARRAYS, {"float64_values": [0.0, math.inf, 0.0]}) == ("float64_values[1]", "non_finite")
    assert refused(ARRAYS, {"basic_types_values": [{}, {"x": 1}, {}]}) == ("basic_types_values[1].x", "unknown_field")
    assert refused(ARRAYS, {"string_values": "abc"}) == ("string_values", "bad_type")


def test_bounded_sequences_and_strings():
    assert refused(BOUNDED, {"int32_values": [1, 2, 3, 4]}) == ("int32_values", "too_long")
    assert list(build(BOUNDED, {"int32_values": [1, 2]}).int32_values) == [1, 2]
    assert refused(STRINGS, {"bounded_string_value": "x" * 23}) == ("bounded_string_value", "too_long")
    assert refused(STRINGS, {"string_value": "a\x00b"}) == ("string_value", "bad_value")
    assert refused(STRINGS, {"string_value": 5}) == ("string_value", "bad_type")


def test_descriptions_for_forms():
    fields = {f["name"]: f for f in describe(ARRAYS)}
    assert fields["int32_values"]["kind"] == "array" and fields["int32_values"]["size"] == 3
    assert fields["int32_values"]["item"] == {"kind": "int", "min": -2**31, "max": 2**31 - 1}
    bounded = {f["name"]: f for f in describe(BOUNDED)}
    assert bounded["int32_values"]["max_items"] == 3
    pose = {f["name"]: f for f in describe(POSE)}
    assert pose["pose"]["kind"] == "message" and pose["pose"]["fields"][0]["name"] == "position"


@pytest.mark.parametrize("name", ["os/srv/Thing", "json/action/X", "std_srvs/srv/Nope", "std_srvs/msgs/Trigger",
                                  "std_srvs/srv/trigger", "std_srvs/srv/Trigger\n", "../srv/X", 5])
def test_only_interface_packages_are_imported(name):
    with pytest.raises(UnknownMessageType):
        interface_class(name)


def test_services_and_actions_by_name():
    assert interface_class("std_srvs/srv/SetBool").Request.get_fields_and_field_types() == {"data": "boolean"}
    assert hasattr(interface_class("test_msgs/action/Fibonacci"), "Goal")
