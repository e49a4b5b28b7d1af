"""What a long-lived response (SSE, MJPEG, topic echo) can learn of its browser's socket."""

from __future__ import annotations

import socket


def peer_gone(sock) -> bool:
    """True once the client closed its end: a streaming response may stop instead of waiting for a
    write to fail (which can take minutes when nothing new is sent)."""
    if sock is None:
        return False
    try:
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True
