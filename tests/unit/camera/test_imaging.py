"""Every supported pixel layout becomes a JPEG of the right size and roughly the right colours."""

import io

import numpy as np
import pytest
from PIL import Image

from rover_web.camera.imaging import (
    CompressedFrame,
    FrameError,
    RawImage,
    encode_compressed,
    encode_frame,
    encode_raw,
    error_frame,
    image_to_array,
    output_size,
)

W, H = 48, 32
LEFT, RIGHT = (200, 30, 60), (20, 180, 90)  # a red half and a green half


def decode(jpeg: bytes) -> Image.Image:
    return Image.open(io.BytesIO(jpeg))


def close_to(pixel, expected, tolerance=14):
    return all(abs(int(a) - int(b)) <= tolerance for a, b in zip(pixel, expected, strict=True))


def two_halves(channels_for_colour, bpp, pad=5):
    """Rows with `pad` bytes of padding after the pixels, to prove `step` is honoured."""
    step = W * bpp + pad
    data = bytearray(step * H)
    for y in range(H):
        for x in range(W):
            colour = LEFT if x < W // 2 else RIGHT
            data[y * step + x * bpp:y * step + (x + 1) * bpp] = bytes(channels_for_colour(colour))
        data[y * step + W * bpp:(y + 1) * step] = b"\xee" * pad  # padding must never show up
    return step, bytes(data)


COLOUR_LAYOUTS = {
    "rgb8": (3, lambda c: c),
    "bgr8": (3, lambda c: c[::-1]),
    "rgba8": (4, lambda c: (*c, 255)),
    "bgra8": (4, lambda c: (*c[::-1], 0)),  # alpha is dropped, not blended: transparent still shows
}


@pytest.mark.parametrize("encoding", COLOUR_LAYOUTS)
def test_colour_encodings_keep_colours_and_size(encoding):
    bpp, channels = COLOUR_LAYOUTS[encoding]
    step, data = two_halves(channels, bpp)
    jpeg = encode_raw(RawImage(W, H, encoding, step, False, data), quality=95)
    picture = decode(jpeg.data)
    assert picture.format == "JPEG" and picture.size == (W, H) and (jpeg.width, jpeg.height) == (W, H)
    assert close_to(picture.convert("RGB").getpixel((6, H // 2)), LEFT)
    assert close_to(picture.convert("RGB").getpixel((W - 6, H // 2)), RIGHT)


@pytest.mark.parametrize("encoding", ["mono8", "8UC1"])
def test_mono8(encoding):
    step, data = two_halves(lambda c: (c[0],), 1)
    picture = decode(encode_raw(RawImage(W, H, encoding, step, False, data), 95).data)
    assert picture.mode == "L" and picture.size == (W, H)
    assert abs(picture.getpixel((6, H // 2)) - LEFT[0]) <= 10
    assert abs(picture.getpixel((W - 6, H // 2)) - RIGHT[0]) <= 10


@pytest.mark.parametrize("big_endian", [False, True])
@pytest.mark.parametrize("encoding", ["mono16", "16UC1"])
def test_mono16_is_stretched_from_its_valid_range_in_either_byte_order(encoding, big_endian):
    # A depth image in millimetres: 0 (no reading) on the left quarter, 1000..3000 mm across the rest.
    values = np.zeros((H, W), np.uint16)
    values[:, W // 4:] = np.linspace(1000, 3000, W - W // 4, dtype=np.uint16)[None, :]
    data = values.astype(">u2" if big_endian else "<u2").tobytes()
    picture = decode(encode_raw(RawImage(W, H, encoding, W * 2, big_endian, data), 95).data)
    assert picture.size == (W, H) and picture.mode == "L"
    row = [picture.getpixel((x, H // 2)) for x in (2, W // 4 + 1, W // 2 + 4, W - 1)]
    assert row[0] <= 10  # no reading stays black
    assert row[1] <= 20  # the nearest reading is the darkest shown
    assert 100 <= row[2] <= 170
    assert row[3] >= 235  # the farthest is white
    # Read with the wrong byte order the ramp would not rise steadily; it does here.
    assert row[1] < row[2] < row[3]


def test_32fc1_depth_in_metres_ignores_nan():
    values = np.full((H, W), np.nan, np.float32)
    values[:, W // 2:] = np.linspace(0.5, 4.0, W - W // 2, dtype=np.float32)[None, :]
    picture = decode(encode_raw(RawImage(W, H, "32FC1", W * 4, False, values.tobytes()), 95).data)
    assert picture.getpixel((2, 2)) <= 10 and picture.getpixel((W - 1, 2)) >= 235


def test_flat_mono16_is_mid_grey():
    data = np.full((H, W), 500, "<u2").tobytes()
    assert abs(decode(encode_raw(RawImage(W, H, "mono16", W * 2, False, data), 95).data).getpixel((5, 5)) - 128) <= 6


def test_resize_exact_and_by_aspect_ratio():
    step, data = two_halves(lambda c: c, 3)
    image = RawImage(W, H, "rgb8", step, False, data)
    assert decode(encode_raw(image, 80, width=24).data).size == (24, 16)
    assert decode(encode_raw(image, 80, height=64).data).size == (96, 64)
    picture = decode(encode_raw(image, 90, width=10, height=30).data)
    assert picture.size == (10, 30)
    assert close_to(picture.convert("RGB").getpixel((1, 15)), LEFT, 25)
    assert output_size(640, 480, None, None) == (640, 480)


def test_a_derived_size_is_scaled_down_to_the_output_area():
    """width=4096 of a 4×16384 source would otherwise be a 4096×16777216 image."""
    w, h = output_size(4, 16384, 4096, None, max_pixels=1_000_000)
    assert w * h <= 1_000_000 and abs(h / w / 4096 - 1) < 0.1  # the aspect ratio is kept (to a pixel)
    assert output_size(8000, 8000, None, None, max_pixels=1_000_000) == (1000, 1000)
    assert output_size(640, 480, None, None, max_pixels=1_000_000) == (640, 480)
    step, data = two_halves(lambda c: c, 3)
    tall = RawImage(W, H, "rgb8", step, False, data)
    w, h = decode(encode_raw(tall, 80, height=3200, max_pixels=100_000).data).size
    assert w * h <= 100_000 and abs(w / h - W / H) < 0.05


def test_quality_changes_the_size():
    rng = np.random.default_rng(1)
    data = rng.integers(0, 255, (H, W, 3), dtype=np.uint8).tobytes()
    image = RawImage(W, H, "rgb8", W * 3, False, data)
    assert len(encode_raw(image, 10).data) < len(encode_raw(image, 95).data)


@pytest.mark.parametrize("image, code", [
    (RawImage(W, H, "yuv422", W * 2, False, bytes(W * H * 2)), "unsupported_encoding"),
    (RawImage(W, H, "bayer_rggb8", W, False, bytes(W * H)), "unsupported_encoding"),
    (RawImage(W, H, "rgb8", W * 3, False, bytes(W * 3 * (H - 1))), "short_data"),
    (RawImage(W, H, "rgb8", W * 2, False, bytes(W * 3 * H)), "bad_step"),
    (RawImage(0, H, "rgb8", 0, False, b""), "empty_image"),
    (RawImage(100000, 100000, "mono8", 100000, False, b""), "image_too_large"),
])
def test_unshowable_images_are_refused_with_a_reason(image, code):
    with pytest.raises(FrameError) as info:
        image_to_array(image)
    assert info.value.code == code
    # A stream that has started shows the reason on an error frame instead.
    jpeg = encode_frame(image, 80)
    assert jpeg.error_code == code and str(info.value) == jpeg.error
    assert decode(jpeg.data).format == "JPEG"


def test_last_row_without_padding_is_accepted():
    step, data = two_halves(lambda c: c, 3, pad=4)
    picture = decode(encode_raw(RawImage(W, H, "rgb8", step, False, data[:-4]), 95).data)
    assert close_to(picture.convert("RGB").getpixel((W - 6, H - 2)), RIGHT)


def jpeg_file(colour=LEFT, size=(W, H)) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", size, colour).save(out, "JPEG", quality=90)
    return out.getvalue()


def test_compressed_jpeg_passes_through_untouched():
    original = jpeg_file()
    jpeg = encode_compressed(CompressedFrame("rgb8; jpeg compressed bgr8", original, stamp=3.5), quality=10)
    assert jpeg.data == original and jpeg.passthrough and (jpeg.width, jpeg.height) == (W, H) and jpeg.stamp == 3.5
    # Asking for its own size is still a pass-through; another size re-encodes.
    assert encode_compressed(CompressedFrame("jpeg", original), 80, width=W).passthrough
    scaled = encode_compressed(CompressedFrame("jpeg", original), 80, width=W // 2)
    assert not scaled.passthrough and decode(scaled.data).size == (W // 2, H // 2)
    assert close_to(decode(scaled.data).convert("RGB").getpixel((3, 3)), LEFT, 20)


def test_png_is_decoded_and_encoded_as_jpeg():
    out = io.BytesIO()
    Image.new("RGBA", (W, H), (*RIGHT, 255)).save(out, "PNG")
    jpeg = encode_compressed(CompressedFrame("png", out.getvalue()), 90)
    assert not jpeg.passthrough and decode(jpeg.data).format == "JPEG"
    assert close_to(decode(jpeg.data).convert("RGB").getpixel((4, 4)), RIGHT)


def test_16_bit_png_is_stretched():
    values = np.zeros((H, W), np.uint16)
    values[:, W // 2:] = 4000
    values[:, -4:] = 8000
    out = io.BytesIO()
    Image.fromarray(values).save(out, "PNG")
    picture = decode(encode_compressed(CompressedFrame("mono16; png compressed", out.getvalue()), 95).data)
    assert picture.getpixel((2, 2)) <= 10 and picture.getpixel((W - 1, 2)) >= 235


@pytest.mark.parametrize("frame, code", [
    (CompressedFrame("16UC1; compressedDepth png", b"\x00" * 12 + b"\x89PNG"), "unsupported_encoding"),
    (CompressedFrame("jpeg", b"not an image at all"), "bad_image"),
])
def test_bad_compressed_frames(frame, code):
    with pytest.raises(FrameError) as info:
        encode_compressed(frame, 80)
    assert info.value.code == code


def test_error_frame_is_a_jpeg_of_the_asked_size():
    jpeg = error_frame("image encoding 'yuv422' is not supported", "unsupported_encoding", width=320)
    assert decode(jpeg.data).size == (320, 180) and jpeg.error.startswith("image encoding")


EPS = (b"%!PS-Adobe-3.0 EPSF-3.0\n%%BoundingBox: 0 0 8 8\nnewpath 0 0 moveto 8 8 lineto stroke\n"
       b"showpage\n%%EOF\n")


@pytest.mark.parametrize("fmt", ["BMP", "GIF", "TIFF", "ICO", "EPS"])
def test_compressed_images_are_decoded_only_as_jpeg_or_png(fmt):
    """A publisher's bytes never reach Pillow's other decoders (EPS runs Ghostscript)."""
    if fmt == "EPS":
        data = EPS
    else:
        out = io.BytesIO()
        Image.new("RGB", (W, H), LEFT).save(out, fmt)
        data = out.getvalue()
    with pytest.raises(FrameError) as info:
        encode_compressed(CompressedFrame("jpeg", data), 80)
    assert info.value.code == "bad_image"

