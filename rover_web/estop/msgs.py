"""The e-stop's message: std_msgs/Bool, true while engaged (twist_mux's "lock" topic type)."""

from __future__ import annotations

from std_msgs.msg import Bool

MSG_TYPE = "std_msgs/msg/Bool"


def flag(engaged: bool) -> Bool:
    return Bool(data=bool(engaged))
