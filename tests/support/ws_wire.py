"""RFC 6455 on the wire, the client's side, for tests that must write frames a library would
refuse to (unmasked, reserved bits, bad lengths) or read exactly what the server sent."""

from __future__ import annotations

import json
import socket
import struct

from rover_web.teleop.ws_frames import unmask

KEY = b"\x11\x22\x33\x44"


def masked(first: int, payload: bytes, *, length: bytes | None = None, mask_bit: bool = True,
           key: bytes = KEY) -> bytes:
    """A client frame built by hand: `first` is the whole first byte (FIN, RSV, opcode)."""
    n = len(payload)
    if length is None:
        length = bytes([n]) if n < 126 else (bytes([126]) + struct.pack("!H", n) if n < 1 << 16
                                             else bytes([127]) + struct.pack("!Q", n))
    length = bytes([length[0] | (0x80 if mask_bit else 0)]) + length[1:]
    return bytes([first]) + length + (key + unmask(payload, key) if mask_bit else payload)


def text(message) -> bytes:
    """One final text frame; dicts are sent as JSON."""
    return masked(0x81, (message if isinstance(message, str) else json.dumps(message)).encode())


def close(code: int) -> bytes:
    return masked(0x88, struct.pack("!H", code))


def _exactly(sock: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise EOFError(f"connection ended after {len(data)} of {n} bytes")
        data += chunk
    return data


def read_frame(sock: socket.socket) -> tuple[int, bytes]:
    """(opcode, payload) of the server's next frame; EOFError when the connection has ended."""
    b0, b1 = _exactly(sock, 2)
    assert b0 & 0x80 and not b0 & 0x70 and not b1 & 0x80, "a server frame: final, no RSV bits, unmasked"
    size = b1 & 0x7F
    if size == 126:
        size = struct.unpack("!H", _exactly(sock, 2))[0]
    elif size == 127:
        size = struct.unpack("!Q", _exactly(sock, 8))[0]
    return b0 & 0x0F, _exactly(sock, size)
