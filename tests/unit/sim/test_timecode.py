"""The camera's time code survives JPEG at quality 30 and scaling, and reads back exactly."""

import io

import numpy as np
import pytest
from PIL import Image

from rover_web.sim import timecode
from rover_web.sim.camera import PatternFrames

NOW_MS = 1_795_000_000_123  # November 2026


def jpeg_round_trip(image: np.ndarray, quality: int = 30, scale: float = 1.0) -> np.ndarray:
    pil = Image.fromarray(image)
    if scale != 1.0:
        pil = pil.resize((round(pil.width * scale), round(pil.height * scale)), Image.BILINEAR)
    buf = io.BytesIO()
    pil.save(buf, "JPEG", quality=quality)
    return np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"))


@pytest.mark.parametrize("stamp", [NOW_MS, NOW_MS + 987, NOW_MS - 40_000, 0xFFFFFFFF, 0x100000000, 0xAAAAAAAA5555])
def test_a_camera_frame_reads_back_after_jpeg_at_quality_30(stamp):
    frames = PatternFrames(640, 480, noise=12.0)
    image = frames.frame(3, stamp / 1000)
    assert timecode.read(jpeg_round_trip(image), now_ms=stamp + 250) == stamp


@pytest.mark.parametrize("scale", [0.5, 0.25])
def test_it_reads_back_after_scaling_down(scale):
    image = PatternFrames(640, 480, noise=12.0).frame(0, NOW_MS / 1000)
    small = jpeg_round_trip(image, scale=scale)
    assert small.shape[1] == 640 * scale
    assert timecode.read(small, now_ms=NOW_MS + 1500) == NOW_MS


def test_every_bit_is_carried():
    for bit in range(32):
        stamp = NOW_MS - NOW_MS % (1 << 32) + (1 << bit)
        image = np.full((240, 320, 3), 128, np.uint8)
        timecode.draw(image, stamp)
        assert timecode.read(jpeg_round_trip(image), now_ms=stamp) == stamp


def test_the_high_bits_come_from_the_receivers_clock_across_a_wrap():
    stamp = (5 << 32) - 10  # sent just before the low bits wrap, received just after
    image = np.zeros((480, 640, 3), np.uint8)
    timecode.draw(image, stamp)
    assert timecode.read(image, now_ms=(5 << 32) + 300) == stamp


def test_an_image_without_a_code_reads_as_none():
    assert timecode.read(np.full((480, 640, 3), 200, np.uint8)) is None
    noise = np.random.default_rng(1).integers(0, 256, (480, 640, 3), dtype=np.uint8)
    assert timecode.read(noise) is None
    assert timecode.read(np.zeros((10, 10, 3), np.uint8)) is None


def test_a_damaged_code_is_refused_not_misread():
    image = np.full((480, 640, 3), 128, np.uint8)
    timecode.draw(image, NOW_MS)
    cell = 640 / 24
    x = round(cell / 2 + 5 * cell + cell / 2)  # flip one data bit of the first row
    y = round(480 - 2 * cell - cell / 2 + cell / 2)
    image[y - 5:y + 5, x - 5:x + 5] = 255 - image[y, x]
    assert timecode.read(image, now_ms=NOW_MS) is None  # the row's parity no longer holds


def test_small_images_get_no_code():
    image = np.full((48, 64, 3), 77, np.uint8)
    timecode.draw(image, NOW_MS)
    assert (image == 77).all()


@pytest.mark.parametrize("codec, container", [("libvpx", "webm"), ("libx264", "mp4")])
def test_it_survives_a_video_codec_at_a_low_bitrate(codec, container):
    """VP8 and H.264 at 150 kbit/s and 320×240 (PyAV, when installed: the WebRTC path's codecs)."""
    av = pytest.importorskip("av")
    frames = PatternFrames(640, 480, noise=12.0)
    buf = io.BytesIO()
    with av.open(buf, "w", format=container) as out:
        stream = out.add_stream(codec, rate=30)
        stream.width, stream.height, stream.pix_fmt, stream.bit_rate = 320, 240, "yuv420p", 150_000
        stamps = [NOW_MS + n * 33 for n in range(45)]
        for n, stamp in enumerate(stamps):
            frame = av.VideoFrame.from_ndarray(frames.frame(n, stamp / 1000), format="rgb24")
            for packet in stream.encode(frame.reformat(width=320, height=240)):
                out.mux(packet)
        for packet in stream.encode():
            out.mux(packet)
    buf.seek(0)
    with av.open(buf) as received:
        read = [timecode.read(f.to_ndarray(format="rgb24"), now_ms=NOW_MS) for f in received.decode(video=0)]
    assert read == stamps
