"""GET /api/events?channels=a,b — the one Server-Sent Events stream a page opens."""

from __future__ import annotations

import socket
import ssl
import time

from flask import Blueprint, Response, request, stream_with_context

from rover_web.auth import on_revoke
from rover_web.core.state import current_rover
from rover_web.events.hub import TooManyClients
from rover_web.web.api_messages import text_of
from rover_web.web.connection import peer_gone
from rover_web.web.streams import held_by, stream_slot

from .http import ApiError

bp = Blueprint("sse", __name__)

# How often an idle stream checks that its browser is still there, so a closed tab frees its
# thread within about a second rather than at the next failed write.
_LIVENESS_CHECK_S = 1.0


def _parse_channels(raw: str, known: frozenset[str]) -> list[str]:
    channels = [c for c in (part.strip() for part in raw.split(",")) if c]
    if not channels:
        raise ApiError(400, "missing_channels",
                       "name channels, e.g. ?channels=status; known: %(known)s",
                       known=', '.join(sorted(known)))
    unknown = [c for c in channels if c not in known]
    if unknown:
        raise ApiError(400, "unknown_channel",
                       "unknown channel(s) %(value)s; known: %(known)s",
                       value=', '.join(c[:32] for c in unknown[:5]), known=', '.join(sorted(known)))
    return channels


_SEND_BUFFER_BYTES = 64 * 1024
_HEAD = (b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-cache\r\n"
         b"X-Accel-Buffering: no\r\nConnection: close\r\n\r\n")


def _serve_on_socket(rover, sock, subscription, retry: bytes) -> Response:
    """Write the head and snapshot here, then let the Broadcaster own the stream until it ends.

    The body is delimited by closing the connection (no chunked framing), and this thread only
    waits, so the server does not reuse or close the socket while the Broadcaster writes to it.
    """
    try:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        # A small kernel buffer bounds what a stalled browser can hold up; the rest is conflated.
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, _SEND_BUFFER_BYTES)
        sock.sendall(_HEAD + retry + subscription.snapshot())
    except OSError:
        subscription.close()
        return Response(status=204)
    stream = rover.broadcaster.attach(sock, subscription)
    with on_revoke(lambda _reason: rover.broadcaster.end(stream)):  # its user's access ended: end it
        stream.wait()
    # The server will try to send a response on the shut-down socket and treat it as a dropped
    # connection; nothing reaches the browser.
    return Response(status=204)


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
    slot = stream_slot("sse")
    try:
        subscription = hub.subscribe(channels, last_event_id)
    except TooManyClients as exc:
        slot.release()
        raise ApiError(503, "too_many_streams", "%(why)s; close some tabs", why=text_of(exc)) from None
    keepalive_s = config["ROVER_WEB_SSE_KEEPALIVE_S"]
    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    retry = f"retry: {config['ROVER_WEB_SSE_RETRY_MS']}\n\n".encode()
    # The Broadcaster writes plain TCP sockets itself, many per thread; a TLS stream is written by
    # its own request thread through the TLS layer (the generator below).
    if (sock is not None and not isinstance(sock, ssl.SSLSocket)
            and request.environ.get("SERVER_PROTOCOL", "").startswith("HTTP/1.")):
        with slot:
            return _serve_on_socket(rover, sock, subscription, retry)

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
                elif peer_gone(sock):
                    return

    return held_by(Response(stream_with_context(stream()), mimetype="text/event-stream",
                            headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"}), slot)
