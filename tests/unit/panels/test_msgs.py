"""Building std_msgs commands and reading display fields (rover_web/ros/panel_msgs.py)."""

import math

import pytest
from geometry_msgs.msg import Point
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float32

from rover_web.panels.msgs import field_kind, read_field, scalar_message
from rover_web.panels.scalars import SCALAR_TYPES

EXAMPLES = {
    "Bool": True, "Byte": 200, "Char": 65, "Int8": -128, "UInt8": 255, "Int16": -32768, "UInt16": 65535,
    "Int32": -2**31, "UInt32": 2**32 - 1, "Int64": -2**63, "UInt64": 2**64 - 1, "Float32": 0.5,
    "Float64": 1e300, "String": "take off",
}


@pytest.mark.parametrize("short", sorted(EXAMPLES))
def test_every_scalar_type_builds_and_reads_back(short):
    type_name = f"std_msgs/msg/{short}"
    assert type_name in SCALAR_TYPES
    msg = scalar_message(type_name, EXAMPLES[short])
    assert type(msg).__name__ == short
    assert read_field(msg, "data") == EXAMPLES[short]


def test_covers_every_std_msgs_scalar():
    assert {t.split("/")[-1] for t in SCALAR_TYPES} == set(EXAMPLES)


def test_float_fields_get_floats_and_byte_gets_one_octet():
    assert isinstance(scalar_message("std_msgs/msg/Float64", 3).data, float)
    assert scalar_message("std_msgs/msg/Byte", 7).data == b"\x07"


def test_read_field_makes_values_json_ready():
    assert read_field(Point(x=1.0, y=2.0, z=3.0), "") == {"x": 1.0, "y": 2.0, "z": 3.0}
    assert read_field(Float32(data=math.nan), "data") == "nan"
    fix = NavSatFix(latitude=27.5)
    fix.header.frame_id = "gps"
    assert read_field(fix, "header.frame_id") == "gps"
    assert read_field(fix, "latitude") == 27.5
    assert read_field(fix, "position_covariance") == [0.0] * 9


def test_field_kind():
    assert field_kind("std_msgs/msg/String", "data") == "string"
    assert field_kind("std_msgs/Int8", "data") == "int"
    assert field_kind("std_msgs/msg/Bool", "data") == "bool"
    assert field_kind("geometry_msgs/msg/Point", "") == "message"
    assert field_kind("sensor_msgs/msg/NavSatFix", "header") == "message"
    assert field_kind("sensor_msgs/msg/NavSatFix", "header.stamp.sec") == "int"
    assert field_kind("sensor_msgs/msg/NavSatFix", "altitude") == "float"
    assert field_kind("sensor_msgs/msg/NavSatFix", "position_covariance") == "other"
    with pytest.raises(ValueError, match="has no field 'lat'"):
        field_kind("sensor_msgs/msg/NavSatFix", "lat")
    with pytest.raises(ValueError, match="no field"):
        field_kind("sensor_msgs/msg/NavSatFix", "altitude.x")
    with pytest.raises(LookupError):
        field_kind("nosuch_msgs/msg/Thing", "data")
