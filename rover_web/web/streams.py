"""A view's share of the stream cap: a slot taken before a long-lived response starts, or 503."""

from __future__ import annotations

from flask import Response

from rover_web.core.state import current_rover
from rover_web.core.streams import StreamSlot, TooManyStreams
from rover_web.web.http import ApiError


def stream_slot(kind: str) -> StreamSlot:
    """Take a slot for a stream about to start; 503 `too_many_streams` when the cap is reached."""
    try:
        return current_rover().streams.acquire(kind)
    except TooManyStreams as exc:
        raise ApiError(503, "too_many_streams", str(exc)) from None


def held_by(response: Response, slot: StreamSlot) -> Response:
    """Give the slot back when the server closes the response, however the stream ended
    (a generator that never started has no `finally` to do it)."""
    response.call_on_close(slot.release)
    return response
