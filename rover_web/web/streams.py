"""A view's share of the stream cap: a slot taken before a long-lived response starts, or 503."""

from __future__ import annotations

import ipaddress
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from flask import Response, current_app, request
from flask_login import current_user

from rover_web.core.state import current_rover
from rover_web.core.streams import StreamSlot, TooManyStreams
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError

# Kinds that may take the reserved slots whoever asks: driving must never find the cap full.
_DRIVING = frozenset({"teleop"})


def sign_in_on() -> bool:
    from rover_web.auth.service import AuthService  # here: web/ is below the features it serves

    try:
        return current_rover().feature(AuthService).sign_in_on()
    except Exception:  # an app built without the auth feature (some tests): nobody signs in
        return False


def refuse_cross_site() -> None:
    """403 for a request another site's page made (`Sec-Fetch-Site: cross-site`) while sign-in is
    off. Such a GET (an <img src> or EventSource on any web page the operator visits) would create
    subscriptions and streams on the robot with nobody's consent; with sign-in on, the session
    cookie is SameSite=Strict and such a request is not signed in. Tools that are not browsers send no header."""
    if request.headers.get("Sec-Fetch-Site", "").lower() == "cross-site" and not sign_in_on():
        raise ApiError(403, "cross_site", "another site's page may not open streams or subscriptions on this "
                                          "robot; open the GUI itself")


def client_key() -> str | None:
    """Whose share a stream counts against: the signed-in user, else the address it came from.
    None (no share) for a loopback address without sign-in: that is the robot itself or a reverse
    proxy on it, whose every client would share one address; the reserve still keeps driving free."""
    if current_user and current_user.is_authenticated:
        return f"user:{current_user.name}"
    try:
        if ipaddress.ip_address(request.remote_addr or "").is_loopback:
            return None
    except ValueError:
        pass
    return f"addr:{request.remote_addr}"


def _may_reserve(kind: str) -> bool:
    if kind in _DRIVING:
        return True
    return bool(current_user and current_user.is_authenticated
                and getattr(current_user, "role", None) in ("operator", "admin") and sign_in_on())


def stream_slot(kind: str) -> StreamSlot:
    """Take a slot for a stream about to start: 403 for another site's page with sign-in off,
    503 `too_many_streams` when the cap, the client's share or all but the reserve is taken."""
    refuse_cross_site()
    config = current_app.config
    share = None if kind in _DRIVING else config["ROVER_WEB_MAX_STREAMS_PER_CLIENT"]
    try:
        return current_rover().streams.acquire(kind, client_key(), share,
                                               config["ROVER_WEB_STREAMS_RESERVED"], _may_reserve(kind))
    except TooManyStreams as exc:
        raise ApiError(503, "too_many_streams", text_of(exc)) from None


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
