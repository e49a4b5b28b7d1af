"""GET /api/events?channels=a,b — the one Server-Sent Events stream a page opens."""

from __future__ import annotations

import socket
import time

from flask import Blueprint, Response, request, stream_with_context

from .core import current_rover
from .events import TooManyClients
from .http import ApiError

bp = Blueprint("sse", __name__)

# How often an idle stream checks that its browser is still there, so a closed tab frees its
# thread within about a second rather than at the next failed write.
_LIVENESS_CHECK_S = 1.0


def _peer_gone(sock) -> bool:
    if sock is None:
        return False
    try:
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True


def _parse_channels(raw: str, known: frozenset[str]) -> list[str]:
    channels = [c for c in (part.strip() for part in raw.split(",")) if c]
    if not channels:
        raise ApiError(400, "missing_channels", f"name channels, e.g. ?channels=status; known: {', '.join(sorted(known))}")
    unknown = [c for c in channels if c not in known]
    if unknown:
        raise ApiError(400, "unknown_channel",
                       f"unknown channel(s) {', '.join(c[:32] for c in unknown[:5])}; known: {', '.join(sorted(known))}")
    return channels


@bp.get("/api/events")
def events():
    rover = current_rover()
    hub, config = rover.hub, rover.config
    channels = _parse_channels(request.args.get("channels", ""), hub.channels)
    last_id = request.headers.get("Last-Event-ID") or request.args.get("lastEventId")
    try:
        last_event_id = int(last_id) if last_id else None
    except ValueError:
        last_event_id = None
    try:
        subscription = hub.subscribe(channels, last_event_id)
    except TooManyClients as exc:
        raise ApiError(503, "too_many_streams", f"{exc}; close some tabs") from None
    keepalive_s = config["ROVER_WEB_SSE_KEEPALIVE_S"]
    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    retry = f"retry: {config['ROVER_WEB_SSE_RETRY_MS']}\n\n".encode()

    def stream():
        with subscription:
            yield retry + subscription.snapshot()
            last_write = time.monotonic()
            while True:
                chunk = subscription.wait(min(keepalive_s, _LIVENESS_CHECK_S))
                if chunk is None:
                    return
                now = time.monotonic()
                if chunk:
                    yield chunk
                    last_write = now
                elif now - last_write >= keepalive_s:
                    yield b": keep-alive\n\n"
                    last_write = now
                elif _peer_gone(sock):
                    return

    return Response(stream_with_context(stream()), mimetype="text/event-stream",
                    headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})
