"""A view's share of the stream cap: a slot taken before a long-lived response starts, or 503."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

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


@contextmanager
def opening(kind: str) -> Iterator[StreamSlot]:
    """A slot for a stream being opened; given back if opening it fails (a 4xx, say)."""
    slot = stream_slot(kind)
    try:
        yield slot
    except BaseException:
        slot.release()
        raise


def once(*releases: Callable[[], None]) -> Callable[[], None]:
    """One callable that runs `releases` the first time it is called, whoever calls it first (the
    stream's end, the server's close)."""
    done = threading.Event()
    lock = threading.Lock()

    def release() -> None:
        with lock:
            if done.is_set():
                return
            done.set()
        for fn in releases:
            fn()

    return release
