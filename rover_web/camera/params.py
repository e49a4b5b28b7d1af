"""The query of GET /stream and /snapshot, checked: web_video_server's arguments, plus msg_type. Pure Python."""

from __future__ import annotations

import re
from collections.abc import Mapping

from rover_web.web.validate import InvalidInput, topic_name

QOS_PROFILES = ("default", "sensor_data")
VIEWER_LABEL = re.compile(r"[A-Za-z0-9_-]{1,64}\Z")
# web_video_server's `type` is the stream format; MJPEG is the one this server makes.
STREAM_TYPES = ("mjpeg",)


def _int_arg(args: Mapping[str, str], name: str, low: int, high: int, *, original_ok: bool = False) -> int | None:
    text = args.get(name)
    if text is None or text.strip() == "":
        return None
    text = text.strip()
    try:
        value = int(text, 10)
    except ValueError:
        raise InvalidInput("'%(name)s' must be a whole number, got %(text)s", "bad_type",
                           name=name, text=repr(text[:20])) from None
    if original_ok and value in (0, -1):  # web_video_server's "keep the camera's size"
        return None
    if not low <= value <= high:
        raise InvalidInput("'%(name)s' must be between %(low)s and %(high)s, got %(value)s", "out_of_range",
                           name=name, low=low, high=high, value=value)
    return value


def parse_stream_args(args: Mapping[str, str], *, max_dimension: int, default_quality: int,
                      max_pixels: int | None = None) -> dict:
    """Check a /stream or /snapshot query; the message type and QoS may still be left to the graph."""
    topic = topic_name(args.get("topic"))
    width = _int_arg(args, "width", 1, max_dimension, original_ok=True)
    height = _int_arg(args, "height", 1, max_dimension, original_ok=True)
    if max_pixels and width and height and width * height > max_pixels:
        raise InvalidInput(
            "%(width)s×%(height)s is more than %(max_pixels)s pixels "
            "(ROVER_WEB_CAMERA_MAX_OUTPUT_PIXELS); ask for a smaller size, or one side only",
            "out_of_range",
            width=width,
            height=height,
            max_pixels=max_pixels,
        )
    quality = _int_arg(args, "quality", 1, 100)
    qos = args.get("qos_profile") or None
    if qos is not None and qos not in QOS_PROFILES:
        raise InvalidInput("'qos_profile' must be one of %(qos_profiles)s; got %(qos)s", "bad_value",
                           qos_profiles=', '.join(QOS_PROFILES), qos=repr(qos[:40]))
    stream_type = args.get("type")
    msg_type = args.get("msg_type") or None
    if stream_type and stream_type not in STREAM_TYPES:
        if "/" not in stream_type:
            raise InvalidInput("stream type %(stream_type)s is not supported; this server streams mjpeg",
                               "unsupported_stream_type", stream_type=repr(stream_type[:40]))
        msg_type = msg_type or stream_type  # type=sensor_msgs/msg/Image works too
    return {"topic": topic, "width": width, "height": height,
            "quality": default_quality if quality is None else quality, "qos": qos, "msg_type": msg_type}


def viewer_label(args: Mapping[str, str]) -> str | None:
    """The optional `viewer` a page tags its stream with, to find its own figures in GET /api/camera/viewers."""
    label = args.get("viewer")
    if label is None or label == "":
        return None
    if not VIEWER_LABEL.match(label):
        raise InvalidInput("'viewer' must be 1 to 64 letters, digits, '-' or '_'", "bad_value")
    return label


def wants_acks(args: Mapping[str, str]) -> bool:
    """`ack=1`: the page will acknowledge the bytes it receives (acks.py); `ack=0` or none: it will not."""
    value = args.get("ack")
    if value is None or value in ("", "0"):
        return False
    if value != "1":
        raise InvalidInput("'ack' must be 1 (the page acknowledges what it receives) or 0; got %(value)s",
                           "bad_value", value=repr(value[:20]))
    return True
