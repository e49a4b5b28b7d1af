"""Camera messages to pictures a video encoder takes: RGB (or grey) pixel arrays at the asked size.

The WebRTC counterpart of imaging.encode_frame: the same pixel layouts (imaging.image_to_array),
the same two compressed formats, the same sizes (imaging.output_size), but the result is an
array for av.VideoFrame instead of JPEG bytes. A FrameProducer (stream.py) runs this once per
message, whatever the number of WebRTC viewers, off the ROS executor. Pure Python (numpy, Pillow).
"""

from __future__ import annotations

import io
import time
from dataclasses import dataclass

import numpy as np

from rover_web.camera import imaging
from rover_web.camera.imaging import CompressedFrame, RawImage


@dataclass(frozen=True)
class Picture:
    """Duck-types imaging.Jpeg for FrameProducer's book-keeping (`data`, sizes, error, encode_s)."""

    data: np.ndarray  # H×W×3 RGB or H×W grey, uint8, C-contiguous
    width: int
    height: int
    stamp: float = 0.0
    passthrough: bool = False
    error: str | None = None
    error_code: str | None = None
    encode_s: float = 0.0


def _resized(pixels: np.ndarray, width: int | None, height: int | None, max_pixels: int | None) -> np.ndarray:
    src_h, src_w = pixels.shape[:2]
    size = imaging.output_size(src_w, src_h, width, height, max_pixels)
    size = (max(2, size[0] // 2 * 2), max(2, size[1] // 2 * 2))  # 4:2:0 video wants even sides
    if size == (src_w, src_h):
        return np.ascontiguousarray(pixels)
    from PIL import Image  # as imaging.py: only when a picture is made
    return np.asarray(Image.fromarray(np.ascontiguousarray(pixels)).resize(size, Image.Resampling.BILINEAR))


def to_picture(frame: RawImage | CompressedFrame, width: int | None = None, height: int | None = None,
               max_pixels: int | None = None) -> Picture:
    """FrameError for what cannot be shown (see imaging.py)."""
    started = time.perf_counter()
    if isinstance(frame, RawImage):
        pixels = imaging.image_to_array(frame)
    else:
        pixels = np.asarray(imaging.decode_compressed(frame))
    out = _resized(pixels, width, height, max_pixels)
    return Picture(out, out.shape[1], out.shape[0], frame.stamp, encode_s=time.perf_counter() - started)


def error_picture(message: str, code: str, width: int | None = None, height: int | None = None,
                  max_pixels: int | None = None) -> Picture:
    """The same dark frame with the reason written on it that an MJPEG viewer sees."""
    from PIL import Image

    jpeg = imaging.error_frame(message, code, width, height, max_pixels=max_pixels)
    pixels = _resized(np.asarray(Image.open(io.BytesIO(jpeg.data)).convert("RGB")), None, None, None)
    return Picture(pixels, pixels.shape[1], pixels.shape[0], error=message, error_code=code)
