"""The multipart/x-mixed-replace framing of an MJPEG stream. Pure Python."""

from __future__ import annotations

from .imaging import Jpeg

BOUNDARY = "frame"
MIMETYPE = f"multipart/x-mixed-replace; boundary={BOUNDARY}"
OPENING = f"--{BOUNDARY}\r\n".encode()  # sent first, so the headers go out before the first frame
PART_END = b"\r\n" + OPENING


def multipart_part(jpeg: Jpeg, seq: int | None = None) -> bytes:
    """One JPEG and the boundary after it, so a browser shows the frame as soon as it arrives.
    `seq` (acknowledged streams): the part's number on its stream, from 1, as X-Frame-Seq."""
    numbered = "" if seq is None else f"X-Frame-Seq: {seq}\r\n"
    head = (f"Content-Type: image/jpeg\r\nContent-Length: {len(jpeg.data)}\r\n"
            f"X-Timestamp: {jpeg.stamp:.9f}\r\n{numbered}\r\n").encode()
    return head + jpeg.data + PART_END
