"""sensor_msgs/Image and CompressedImage to the plain frames imaging.py encodes."""

from __future__ import annotations

from rover_web.ros.convert import stamp_to_float

from .imaging import CompressedFrame, RawImage

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED = "sensor_msgs/msg/CompressedImage"
IMAGE_TYPES = (IMAGE, COMPRESSED)

_ALIASES = {"sensor_msgs/Image": IMAGE, "sensor_msgs/CompressedImage": COMPRESSED,
            IMAGE: IMAGE, COMPRESSED: COMPRESSED}


def image_type(name: str) -> str | None:
    """The canonical name of an image message type, or None if `name` is not one."""
    return _ALIASES.get(name)


def raw_image(msg) -> RawImage:
    """No copy: `data` is the message's own array, which nothing modifies after delivery."""
    return RawImage(msg.width, msg.height, msg.encoding, msg.step, bool(msg.is_bigendian), msg.data,
                    stamp_to_float(msg.header.stamp))


def compressed_frame(msg) -> CompressedFrame:
    return CompressedFrame(msg.format, msg.data, stamp_to_float(msg.header.stamp))


def frame_reader(msg_type: str):
    """The function turning a message of `msg_type` into a frame."""
    return compressed_frame if msg_type == COMPRESSED else raw_image
