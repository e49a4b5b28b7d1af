"""How many bytes a TCP socket still holds: sent and not yet acknowledged, or not sent yet.

Linux's SIOCOUTQ (the same number as TIOCOUTQ) on the socket's descriptor. Over TLS it counts
the encrypted bytes, which is what the link carries. Elsewhere (or for a socket the server does
not expose) it is None, and the rate control keeps only its caps (docs/camera.md).
"""

from __future__ import annotations

import fcntl
import struct
import termios

_SIOCOUTQ = getattr(termios, "TIOCOUTQ", None)


def queued_bytes(sock) -> int | None:
    if sock is None or _SIOCOUTQ is None:
        return None
    try:
        return struct.unpack("i", fcntl.ioctl(sock.fileno(), _SIOCOUTQ, b"\0\0\0\0"))[0]
    except (OSError, ValueError):  # closed, or not a socket the kernel can tell about
        return None
