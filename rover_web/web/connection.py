"""What a long-lived response (SSE, MJPEG, topic echo) can learn of its browser's socket."""

from __future__ import annotations

import socket
import ssl


def peer_gone(sock) -> bool:
    """True once the client closed its end: a streaming response may stop instead of waiting for a
    write to fail (which can take minutes when nothing new is sent).

    A streaming client sends nothing after its request, so anything to read means it is going.
    Over TLS the check peeks at the raw TCP bytes under the TLS layer (an SSLSocket refuses recv
    flags): its close_notify alert or its FIN.
    """
    if sock is None:
        return False
    try:
        if isinstance(sock, ssl.SSLSocket):
            return socket.socket.recv(sock, 1, socket.MSG_PEEK | socket.MSG_DONTWAIT) is not None
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True
