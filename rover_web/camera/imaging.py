"""Camera frames to JPEG: pixel layouts of sensor_msgs/Image, resizing, error frames. Pure Python.

Nothing here knows about ROS: rover_web/camera/msgs.py turns a message into a RawImage or a
CompressedFrame, and these functions turn that into JPEG bytes (numpy for the pixel layout,
Pillow, i.e. libjpeg-turbo, for scaling and encoding).

Choices an operator may want to know:
- Alpha (rgba8, bgra8) is dropped, not blended.
- 16-bit and float images (mono16, 16UC1, 32FC1: depth, thermal, IR) are stretched per frame
  from their smallest to their largest valid value; zero (and NaN/inf for floats) means "no
  reading" on depth cameras, so it stays black and does not count towards the range.
- A JPEG CompressedImage is passed through byte for byte (the asked quality does not apply)
  unless a different size is asked for; then, and for PNG (or any other format Pillow reads),
  it is decoded, scaled and encoded at the asked quality. `compressedDepth` images are refused
  (they are not an image file).
- Width and height both given: exactly that size (web_video_server does the same); one given:
  the other follows the aspect ratio.
"""

from __future__ import annotations

import io
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rover_web.web.api_messages import Text, as_text, explain, text_of

if TYPE_CHECKING:
    from PIL import Image, ImageFont

# Pillow is imported by the functions that draw or code pictures: a server whose camera nobody
# watches never loads it (issue 32: idle RSS). numpy is loaded by ROS's message classes anyway.

# Encoding name -> (bytes per pixel, output: "RGB" or "L").
ENCODINGS: dict[str, tuple[int, str]] = {
    "rgb8": (3, "RGB"), "bgr8": (3, "RGB"), "rgba8": (4, "RGB"), "bgra8": (4, "RGB"),
    "mono8": (1, "L"), "8UC1": (1, "L"), "mono16": (2, "L"), "16UC1": (2, "L"), "32FC1": (4, "L"),
}
SUPPORTED = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8", "mono16", "8UC1", "16UC1", "32FC1")

# Larger than any real camera, small enough that one bad message cannot exhaust memory.
MAX_PIXELS = 64 * 1024 * 1024


class FrameError(ValueError):
    """A frame that cannot be shown; the message says why, for an error frame or a 4xx."""

    def __init__(self, message: str, code: str = "bad_image"):
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class RawImage:
    """The fields of a sensor_msgs/Image; `data` is any buffer (array.array, bytes, memoryview)."""

    width: int
    height: int
    encoding: str
    step: int
    is_bigendian: bool
    data: object
    stamp: float = 0.0


@dataclass(frozen=True)
class CompressedFrame:
    """The fields of a sensor_msgs/CompressedImage."""

    format: str
    data: object
    stamp: float = 0.0


@dataclass(frozen=True)
class Jpeg:
    """One frame ready to send: encoded once, shared by every viewer."""

    data: bytes
    width: int
    height: int
    stamp: float = 0.0
    passthrough: bool = False  # the publisher's own JPEG bytes, not re-encoded
    error: str | None = None  # set for an error frame
    error_code: str | None = None
    error_text: Text | None = None  # the error as a Text, for an answer in the request's language
    encode_s: float = 0.0


def image_to_array(image: RawImage) -> np.ndarray:
    """Pixels as an H×W×3 (RGB) or H×W (grey) uint8 array; a view of `data` where possible."""
    if image.encoding not in ENCODINGS:
        raise FrameError(explain("image encoding %(encoding)s is not supported; supported: %(supported)s",
                                 encoding=repr(image.encoding), supported=', '.join(SUPPORTED)),
                         "unsupported_encoding")
    bpp, _ = ENCODINGS[image.encoding]
    width, height, step = int(image.width), int(image.height), int(image.step)
    if width <= 0 or height <= 0:
        raise FrameError(
            explain("image is %(width)s×%(height)s: nothing to show", width=width, height=height), "empty_image"
        )
    if width * height > MAX_PIXELS:
        raise FrameError(explain("image is %(width)s×%(height)s, more than %(max_pixels)s pixels",
                                 width=width, height=height, max_pixels=MAX_PIXELS), "image_too_large")
    if step < width * bpp:
        raise FrameError(explain("step %(step)s is less than width × %(bpp)s bytes (%(value)s) for %(encoding)s",
                                 step=step, bpp=bpp, value=width * bpp, encoding=image.encoding),
                         "bad_step")
    buffer = np.frombuffer(image.data, dtype=np.uint8)
    if buffer.size < step * (height - 1) + width * bpp:
        raise FrameError(
            explain(
                "image data has %(size)s bytes; %(width)s×%(height)s %(encoding)s with step %(step)s needs %(value)s",
                size=buffer.size,
                width=width,
                height=height,
                encoding=image.encoding,
                step=step,
                value=step * height,
            ),
            "short_data",
        )
    if buffer.size < step * height:  # some drivers leave out the last row's padding
        buffer = np.concatenate([buffer, np.zeros(step * height - buffer.size, np.uint8)])
    rows = buffer[:step * height].reshape(height, step)[:, :width * bpp]  # drop row padding
    encoding = image.encoding
    if bpp == 1:
        return rows
    if encoding in ("mono16", "16UC1"):
        values = rows.view(">u2" if image.is_bigendian else "<u2")
        return stretch_to_8bit(values, values > 0)
    if encoding == "32FC1":
        values = rows.view(">f4" if image.is_bigendian else "<f4")
        return stretch_to_8bit(values, np.isfinite(values) & (values != 0))
    pixels = rows.reshape(height, width, bpp)
    if encoding == "rgb8":
        return pixels
    if encoding == "bgr8":
        return pixels[..., ::-1]
    if encoding == "rgba8":
        return pixels[..., :3]
    return pixels[..., 2::-1]  # bgra8


def stretch_to_8bit(values: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Map the valid values' range onto 1..255 (0 stays for invalid); a flat image is mid-grey."""
    out = np.zeros(values.shape, np.uint8)
    if not valid.any():
        return out
    chosen = values[valid].astype(np.float32)
    low, high = float(chosen.min()), float(chosen.max())
    if high > low:
        out[valid] = (1.0 + (chosen - low) * (254.0 / (high - low)) + 0.5).astype(np.uint8)
    else:
        out[valid] = 128
    return out


def output_size(src_width: int, src_height: int, width: int | None, height: int | None,
                max_pixels: int | None = None) -> tuple[int, int]:
    """The size to send: as asked, or keeping the aspect ratio when only one side is given; scaled
    down to `max_pixels` (one side of a tall or wide source would otherwise ask for a huge image)."""
    if width and height:
        size = width, height
    elif width:
        size = width, max(1, round(src_height * width / src_width))
    elif height:
        size = max(1, round(src_width * height / src_height)), height
    else:
        size = src_width, src_height
    if max_pixels and size[0] * size[1] > max_pixels:
        scale = math.sqrt(max_pixels / (size[0] * size[1]))
        size = max(1, int(size[0] * scale)), max(1, int(size[1] * scale))
    return size


def _encode_picture(picture: Image.Image, quality: int, width: int | None, height: int | None, stamp: float,
                    started: float, max_pixels: int | None) -> Jpeg:
    from PIL import Image

    size = output_size(picture.width, picture.height, width, height, max_pixels)
    if size != picture.size:
        picture = picture.resize(size, Image.Resampling.BILINEAR)
    out = io.BytesIO()
    picture.save(out, "JPEG", quality=quality)
    return Jpeg(out.getvalue(), size[0], size[1], stamp, encode_s=time.perf_counter() - started)


def encode_raw(image: RawImage, quality: int, width: int | None = None, height: int | None = None,
               max_pixels: int | None = None) -> Jpeg:
    """A sensor_msgs/Image as JPEG; FrameError for encodings or layouts that cannot be shown."""
    from PIL import Image

    started = time.perf_counter()
    picture = Image.fromarray(np.ascontiguousarray(image_to_array(image)))
    return _encode_picture(picture, quality, width, height, image.stamp, started, max_pixels)


def is_jpeg(data) -> bool:
    head = bytes(memoryview(data)[:3])
    return head == b"\xff\xd8\xff"


IMAGE_FORMATS = ("JPEG", "PNG")


def check_compressed_format(frame: CompressedFrame) -> None:
    if "compresseddepth" in frame.format.lower():
        raise FrameError(explain("compressedDepth images are not supported; view the raw depth topic instead"),
                         "unsupported_encoding")


def decode_compressed(frame: CompressedFrame, data: bytes | None = None,
                      output_size_of: Callable[[int, int], tuple[int, int]] | None = None) -> Image.Image:
    """A CompressedImage's picture, RGB or L (16-bit and float stretched to 8 bits): FrameError for
    what cannot be shown. `output_size_of(w, h)` lets libjpeg scale by 1/2, 1/4 or 1/8 while
    decoding when the output will be smaller."""
    from PIL import Image

    check_compressed_format(frame)
    data = bytes(frame.data) if data is None else data
    try:
        # Only the two formats a camera sends: Pillow would otherwise also parse EPS (through
        # Ghostscript), TIFF, ICO and dozens more from bytes any publisher on the graph chooses.
        picture = Image.open(io.BytesIO(data), formats=IMAGE_FORMATS)
        if picture.width * picture.height > MAX_PIXELS:
            raise FrameError(explain("image is %(width)s×%(height)s, more than %(max_pixels)s pixels",
                                     width=picture.width, height=picture.height, max_pixels=MAX_PIXELS),
                             "image_too_large")
        if picture.format == "JPEG" and output_size_of is not None:
            picture.draft("RGB", output_size_of(picture.width, picture.height))
        picture.load()
    except FrameError:
        raise
    except Exception as exc:  # Pillow raises many types for bad data; all mean "cannot decode"
        raise FrameError(explain("cannot decode the %(value)s image: %(why)s",
                                 value=frame.format or 'compressed', why=text_of(exc)), "bad_image") from None
    if picture.mode in ("I;16", "I;16B", "I;16L", "I", "F"):
        values = np.asarray(picture)
        valid = np.isfinite(values) & (values != 0) if values.dtype.kind == "f" else values > 0
        return Image.fromarray(stretch_to_8bit(values, valid))
    if picture.mode not in ("RGB", "L"):
        return picture.convert("RGB")
    return picture


def encode_compressed(frame: CompressedFrame, quality: int, width: int | None = None,
                      height: int | None = None, max_pixels: int | None = None) -> Jpeg:
    """A sensor_msgs/CompressedImage as JPEG: passed through if it is one and no size is asked."""
    started = time.perf_counter()
    check_compressed_format(frame)
    data = bytes(frame.data)
    if is_jpeg(data):
        size = _jpeg_size(data)
        if size != (0, 0) and output_size(size[0], size[1], width, height, max_pixels) == size:
            return Jpeg(data, size[0], size[1], frame.stamp, passthrough=True,
                        encode_s=time.perf_counter() - started)
    picture = decode_compressed(frame, data, output_size_of=lambda w, h: output_size(w, h, width, height, max_pixels))
    return _encode_picture(picture, quality, width, height, frame.stamp, started, max_pixels)


def _jpeg_size(data: bytes) -> tuple[int, int]:
    """Width and height from the JPEG's start-of-frame header, without decoding it."""
    from PIL import Image

    try:
        with Image.open(io.BytesIO(data), formats=("JPEG",)) as picture:
            return picture.size
    except Exception:
        return 0, 0


_FONT_CACHE: dict[int, ImageFont.ImageFont] = {}


def font(size: int):
    from PIL import ImageFont

    if size not in _FONT_CACHE:
        try:
            _FONT_CACHE[size] = ImageFont.load_default(size)
        except Exception:  # Pillow without FreeType: the small bitmap font
            _FONT_CACHE[size] = ImageFont.load_default()
    return _FONT_CACHE[size]


def error_frame(message: str | Text, code: str, width: int | None = None, height: int | None = None,
                stamp: float = 0.0, max_pixels: int | None = None) -> Jpeg:
    """A dark JPEG with the reason written on it, for a stream that has already started."""
    from PIL import Image, ImageDraw

    size = output_size(640, 360, width, height, max_pixels)
    picture = Image.new("RGB", size, (40, 12, 12))
    draw = ImageDraw.Draw(picture)
    text_size = max(10, min(22, size[0] // 32))
    # Written on the picture in English: one frame goes to every viewer, whatever their language.
    words, lines, line = str(message).split(), [], ""
    per_line = max(10, size[0] // (text_size * 6 // 10))
    for word in words:
        if line and len(line) + 1 + len(word) > per_line:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    lines.append(line)
    draw.text((10, 10), "cannot show this image", fill=(255, 120, 110), font=font(text_size))
    for i, text in enumerate(lines[:12]):
        draw.text((10, 10 + (i + 2) * (text_size + 4)), text, fill=(240, 230, 230), font=font(text_size))
    out = io.BytesIO()
    picture.save(out, "JPEG", quality=80)
    return Jpeg(out.getvalue(), size[0], size[1], stamp, error=str(message), error_code=code,
                error_text=as_text(message, {}))


def encode_frame(frame: RawImage | CompressedFrame, quality: int, width: int | None = None,
                 height: int | None = None, max_pixels: int | None = None) -> Jpeg:
    """Any frame as JPEG; a frame that cannot be shown becomes an error frame saying why."""
    try:
        if isinstance(frame, CompressedFrame):
            return encode_compressed(frame, quality, width, height, max_pixels)
        return encode_raw(frame, quality, width, height, max_pixels)
    except FrameError as exc:
        return error_frame(text_of(exc), exc.code, width, height, getattr(frame, "stamp", 0.0), max_pixels)
