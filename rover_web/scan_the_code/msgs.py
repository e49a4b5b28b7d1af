"""std_msgs/String in and out for Scan the Code: the detector's colour names and the code."""

from __future__ import annotations

from typing import Any

from std_msgs.msg import String

STRING = "std_msgs/msg/String"


def text_of(msg: Any) -> str:
    """The message's text; anything that is not a String message reads as its repr (shown as unknown)."""
    data = getattr(msg, "data", None)
    return data if isinstance(data, str) else repr(msg)


def code_message(colours: list[str]) -> String:
    """The code as the RobotX convention writes it, e.g. "red,green,blue"; a fresh message each call."""
    return String(data=",".join(colours))
