"""A simulated camera: a moving test pattern with a frame counter and timestamp, sensor_msgs/Image rgb8.

640×480 at 30 Hz by default. The pattern (colour bars over a grey ramp) is drawn once; each frame
is a horizontal shift of it (a slice of a twice-as-wide copy) plus a small text box, so the node
uses little CPU however long it runs. Each frame also carries its stamp (the wall clock, ms) as a
machine-readable time code in the bottom-left corner (timecode.py), so a viewer can measure a
frame's age glass to glass, through JPEG, a video codec and any link.
"""

from __future__ import annotations

import argparse
import array
import sys
import time

import numpy as np
from PIL import Image as PilImage
from PIL import ImageDraw
from rclpy.node import Node
from sensor_msgs.msg import Image

from rover_web.camera.imaging import font
from rover_web.ros import qos as qos_profiles

from . import timecode

# SMPTE-like bars: white, yellow, cyan, green, magenta, red, blue, black.
BARS = ((235, 235, 235), (235, 235, 16), (16, 235, 235), (16, 235, 16),
        (235, 16, 235), (235, 16, 16), (16, 16, 235), (16, 16, 16))


def pattern_image(width: int, height: int) -> np.ndarray:
    """Colour bars over the top two thirds, a grey ramp below; H×W×3 uint8."""
    image = np.empty((height, width, 3), np.uint8)
    bars_h = height * 2 // 3
    columns = (np.arange(width) * len(BARS)) // width
    image[:bars_h] = np.asarray(BARS, np.uint8)[columns][None, :, :]
    ramp = np.linspace(0, 255, width, dtype=np.float32).astype(np.uint8)
    image[bars_h:] = ramp[None, :, None]
    return image


class PatternFrames:
    """Frame n is the pattern shifted left by n × speed pixels, with its number and time written on it."""

    def __init__(self, width: int, height: int, speed_px: int = 4, noise: float = 0.0):
        self.width, self.height, self.speed_px = width, height, speed_px
        pattern = pattern_image(width, height)
        if noise > 0:  # sensor-like grain, drawn once: JPEG then works as hard as on a real camera
            grain = np.random.default_rng(0).normal(0.0, noise, pattern.shape)
            pattern = np.clip(pattern + grain, 0, 255).astype(np.uint8)
        self._wide = np.concatenate([pattern, pattern], axis=1)  # any shift is one slice of this
        self._font = font(max(12, height // 24))
        self._box = (min(width, max(160, width * 3 // 5)), min(height, max(20, height // 12)))

    def frame(self, n: int, stamp_s: float) -> np.ndarray:
        offset = (n * self.speed_px) % self.width
        image = self._wide[:, offset:offset + self.width].copy()
        label = PilImage.new("RGB", self._box, (0, 0, 0))
        clock = time.strftime("%H:%M:%S", time.localtime(stamp_s)) + f".{int(stamp_s * 1000) % 1000:03d}"
        ImageDraw.Draw(label).text((6, 2), f"frame {n}  {clock}", fill=(255, 255, 255), font=self._font)
        w, h = self._box
        image[8:8 + h, 8:8 + w] = np.asarray(label)[: self.height - 8, : self.width - 8]
        timecode.draw(image, round(stamp_s * 1000))
        return image


class CameraSim(Node):
    def __init__(self, *, context=None, topic: str = "camera/image_raw", width: int = 640, height: int = 480,
                 rate_hz: float = 30.0, qos: str = "default", frame_id: str = "camera", noise: float = 0.0,
                 namespace: str = "/"):
        super().__init__("sim_camera", namespace=namespace, context=context)
        self.frames = PatternFrames(width, height, noise=noise)
        self.frame_id = frame_id
        self.count = 0
        self.pub = self.create_publisher(Image, topic, qos_profiles.profile(qos))
        self.create_timer(1.0 / rate_hz, self._tick)

    def _tick(self) -> None:
        now = self.get_clock().now()
        pixels = self.frames.frame(self.count, now.nanoseconds * 1e-9)
        msg = Image()
        msg.header.stamp = now.to_msg()
        msg.header.frame_id = self.frame_id
        msg.height, msg.width = pixels.shape[:2]
        msg.encoding = "rgb8"
        msg.is_bigendian = 0
        msg.step = msg.width * 3
        data = array.array("B")
        data.frombytes(pixels.tobytes())  # an array.array is taken as is; a bytes object is checked byte by byte
        msg.data = data
        self.pub.publish(msg)
        self.count += 1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("camera")
    group.add_argument("--camera-topic", default="camera/image_raw",
                       help="image topic (default camera/image_raw, in the robot's namespace)")
    group.add_argument("--camera-size", type=int, nargs=2, metavar=("W", "H"), default=(640, 480),
                       help="image size in pixels (default 640 480)")
    group.add_argument("--camera-hz", type=float, default=30.0, help="frames per second (default 30)")
    # Reliable by default: a best-effort 900 kB frame travels as ~15 UDP fragments and is lost whole
    # when any one overflows the receive buffer, which on a busy machine is a quarter of the frames.
    group.add_argument("--camera-qos", choices=("default", "sensor_data"), default="default",
                       help="publisher QoS: default (reliable) or sensor_data (best effort, as some drivers do)")
    group.add_argument("--camera-noise", type=float, default=0.0, metavar="SIGMA",
                       help="add fixed grain (standard deviation in grey levels) so frames compress like a "
                            "real camera's")


def from_arguments(args: argparse.Namespace, context, namespace: str = "/", east_offset_m: float = 0.0) -> CameraSim:
    width, height = args.camera_size
    if not (16 <= width <= 8192 and 16 <= height <= 8192) or not 0 < args.camera_hz <= 120 \
            or not 0 <= args.camera_noise <= 128:
        raise SystemExit("camera: size must be 16..8192 pixels a side, --camera-hz in (0, 120], --camera-noise 0..128")
    return CameraSim(context=context, topic=args.camera_topic, width=width, height=height, rate_hz=args.camera_hz,
                     qos=args.camera_qos, noise=args.camera_noise, namespace=namespace)


def main(argv: list[str] | None = None) -> None:
    from .runner import run_part
    run_part(sys.modules[__name__], argv)


if __name__ == "__main__":
    main()
