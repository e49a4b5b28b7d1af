"""sensor_msgs/BatteryState read into the `battery` channel: what a driver does not know is None."""

import math

import pytest

pytest.importorskip("sensor_msgs")

from sensor_msgs.msg import BatteryState  # noqa: E402

from rover_web.telemetry.msgs import battery_summary  # noqa: E402


def test_a_level_becomes_a_percent_and_the_status_a_word():
    msg = BatteryState(percentage=0.734, voltage=24.61, power_supply_status=BatteryState.POWER_SUPPLY_STATUS_CHARGING)
    assert battery_summary(msg) == {"percent": 73.4, "voltage": 24.61, "status": "charging", "stamp": 0.0}


def test_unknown_fields_are_none_never_nan():
    msg = BatteryState(percentage=math.nan, voltage=math.nan, power_supply_status=200)
    summary = battery_summary(msg)
    assert summary["percent"] is None and summary["voltage"] is None and summary["status"] == "unknown"
