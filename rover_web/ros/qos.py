"""Named QoS profiles, so configuration and feature code never build QoSProfile by hand."""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data

NAMES = ("default", "sensor_data", "latched", "command")


def profile(name: str = "default", depth: int | None = None) -> QoSProfile:
    """A named profile; `depth` overrides its history depth (10, or 1 for latched and command)."""
    if name == "default":
        return QoSProfile(depth=depth or 10, history=HistoryPolicy.KEEP_LAST,
                          reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
    if name == "sensor_data":
        return qos_profile_sensor_data
    if name == "latched":
        # map_server, amcl and friends publish transient-local: a late joiner still gets the last value.
        return QoSProfile(depth=depth or 1, history=HistoryPolicy.KEEP_LAST,
                          reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    if name == "command":
        # Commands are volatile on purpose: a late subscriber must never receive an old "take off".
        return QoSProfile(depth=depth or 1, history=HistoryPolicy.KEEP_LAST,
                          reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
    raise ValueError(f"unknown QoS profile {name!r}; expected one of {', '.join(NAMES)}")
