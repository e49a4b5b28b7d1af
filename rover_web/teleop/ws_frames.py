"""RFC 6455 frames on the server side of a connection with no extension: parsed as they arrive,
and built for sending. Pure Python, no I/O.

Why not wsproto, which did the handshake: cold, as every 40 Hz joystick frame is (nothing in
the process ran for 25 ms), its parser takes ~150 µs a frame on this machine and this one ~30 µs
(bench/teleop.py and BENCHMARKS.md). The rules are the RFC's, checked against wsproto by
tests/unit/teleop/test_ws_frames.py for any mix of frames and any split of the byte stream.
"""

from __future__ import annotations

import codecs
import struct

OP_CONTINUATION, OP_TEXT, OP_BINARY, OP_CLOSE, OP_PING, OP_PONG = 0x0, 0x1, 0x2, 0x8, 0x9, 0xA

CLOSE_NORMAL = 1000
CLOSE_NO_STATUS = 1005  # "the close frame had no code": never sent
CLOSE_PROTOCOL_ERROR = 1002
CLOSE_INVALID_PAYLOAD = 1007
CLOSE_MESSAGE_TOO_BIG = 1009

# Codes a peer may send (RFC 6455 7.4, as wsproto accepts them): the defined ones that are not
# local-only, and 3000-4999 for libraries and applications.
_PEER_CLOSE_CODES = frozenset({1000, 1001, 1002, 1003, 1007, 1008, 1009, 1010, 1011, 1012, 1013})
MAX_CONTROL_PAYLOAD = 125


class ProtocolError(Exception):
    """The peer broke the protocol; the connection must be closed with `close_code`. `events`
    are those that came complete before the broken frame in the same `feed()`."""

    def __init__(self, close_code: int, message: str):
        super().__init__(message)
        self.close_code, self.message = close_code, message
        self.events: list[tuple[str, object]] = []


def unmask(payload: bytes | bytearray, key: bytes | bytearray) -> bytes:
    """XOR with the 4-byte masking key, as one big-integer operation rather than a byte loop."""
    n = len(payload)
    if not n:
        return b""
    stream = (bytes(key) * ((n + 3) >> 2))[:n]
    return (int.from_bytes(payload, "little") ^ int.from_bytes(stream, "little")).to_bytes(n, "little")


def frame(opcode: int, payload: bytes = b"") -> bytes:
    """One final, unmasked frame, as a server sends them."""
    n = len(payload)
    if n < 126:
        return bytes((0x80 | opcode, n)) + payload
    if n < 1 << 16:
        return struct.pack("!BBH", 0x80 | opcode, 126, n) + payload
    return struct.pack("!BBQ", 0x80 | opcode, 127, n) + payload


def text_frame(text: str) -> bytes:
    return frame(OP_TEXT, text.encode("utf-8"))


def close_frame(code: int, reason: str = "") -> bytes:
    """A close frame with `code` and up to 123 bytes of reason (cut on a character boundary)."""
    if code == CLOSE_NO_STATUS:
        return frame(OP_CLOSE)
    data = reason.encode("utf-8")[:MAX_CONTROL_PAYLOAD - 2].decode("utf-8", "ignore").encode("utf-8")
    return frame(OP_CLOSE, struct.pack("!H", code) + data)


def _close_code_and_reason(payload: bytes) -> tuple[int, str]:
    if not payload:
        return CLOSE_NO_STATUS, ""
    if len(payload) == 1:
        raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a close frame's payload cannot be one byte")
    code = int.from_bytes(payload[:2], "big")
    if code not in _PEER_CLOSE_CODES and not 3000 <= code <= 4999:
        raise ProtocolError(CLOSE_PROTOCOL_ERROR, f"close code {code} may not be sent")
    try:
        return code, payload[2:].decode("utf-8")
    except UnicodeDecodeError:
        raise ProtocolError(CLOSE_INVALID_PAYLOAD, "the close reason is not UTF-8") from None


class FrameParser:
    """Bytes in, complete events out, in order:

      ("text", str) | ("binary", bytes)   a whole message, its fragments joined
      ("ping", bytes) | ("pong", bytes)
      ("close", (code, reason))           code 1005 when the frame had none

    A message whose size (declared in a frame header, so before its payload is buffered) would
    pass `max_message_bytes`, or that comes in more than `max_fragments` frames, raises
    ProtocolError 1009; anything else the RFC forbids, 1002, and text that is not UTF-8, 1007.
    After an error or a close the parser must not be fed again.
    """

    def __init__(self, max_message_bytes: int, max_fragments: int = 64):
        self.max_message_bytes = max_message_bytes
        # Bytes alone do not bound a message: empty fragments cost nothing against them, yet each
        # one is kept and handled. A browser sends a teleop message in one frame.
        self.max_fragments = max_fragments
        # Bytes of a frame still arriving. A bytearray: a big frame trickled in a byte at a time
        # must cost appends, not a copy of everything so far for every byte.
        self._buffer = bytearray()
        self._fragments: list | None = None  # of a message still waiting for its final frame
        self._fragment_bytes = 0
        self._decoder = None  # a text message's incremental UTF-8 decoder; None for binary

    def feed(self, data: bytes) -> list[tuple[str, object]]:
        events: list[tuple[str, object]] = []
        buffer = self._buffer
        if buffer:
            buffer += data
            data = buffer
        try:
            used = self._parse(data, events)
        except ProtocolError as exc:
            exc.events = events
            raise
        if data is buffer:
            del buffer[:used]
        elif used < len(data):
            buffer += data[used:]
        return events

    def _parse(self, buffer: bytes | bytearray, events: list) -> int:
        """Complete frames from the start of `buffer` into `events`; how many bytes they took."""
        start, end = 0, len(buffer)
        while end - start >= 2:
            b0, b1 = buffer[start], buffer[start + 1]
            if b0 & 0x70:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "reserved bits set, but no extension was agreed")
            if not b1 & 0x80:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a client's frames must be masked")
            opcode, final, size = b0 & 0x0F, b0 & 0x80, b1 & 0x7F
            head = start + 6
            if size == 126:
                if end - start < 4:
                    break
                size, head = int.from_bytes(buffer[start + 2:start + 4], "big"), start + 8
                if size < 126:
                    raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a frame length must use the shortest encoding")
            elif size == 127:
                if end - start < 10:
                    break
                size, head = int.from_bytes(buffer[start + 2:start + 10], "big"), start + 14
                if size >> 63:
                    raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a frame length must fit in 63 bits")
                if size < 1 << 16:
                    raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a frame length must use the shortest encoding")
            self._check_header(opcode, final, size)
            if end < head + size:
                break
            payload = unmask(buffer[head:head + size], buffer[head - 4:head])
            start = head + size
            event = self._complete(opcode, final, payload)
            if event is not None:
                events.append(event)
                if event[0] == "close":
                    break
        return start

    def _check_header(self, opcode: int, final: int, size: int) -> None:
        if opcode >= OP_CLOSE:
            if opcode > OP_PONG:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, f"unknown opcode {opcode:#x}")
            if not final:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "control frames may not be fragmented")
            if size > MAX_CONTROL_PAYLOAD:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "control frames carry at most 125 bytes")
            return
        if opcode == OP_CONTINUATION:
            if self._fragments is None:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a continuation frame with no message to continue")
            if len(self._fragments) >= self.max_fragments:
                raise ProtocolError(CLOSE_MESSAGE_TOO_BIG, f"a message may come in at most {self.max_fragments} frames")
            size += self._fragment_bytes
        elif opcode in (OP_TEXT, OP_BINARY):
            if self._fragments is not None:
                raise ProtocolError(CLOSE_PROTOCOL_ERROR, "a new message began before the last one ended")
        else:
            raise ProtocolError(CLOSE_PROTOCOL_ERROR, f"unknown opcode {opcode:#x}")
        if size > self.max_message_bytes:
            raise ProtocolError(CLOSE_MESSAGE_TOO_BIG, f"messages are limited to {self.max_message_bytes} bytes")

    def _complete(self, opcode: int, final: int, payload: bytes) -> tuple[str, object] | None:
        if opcode >= OP_CLOSE:
            if opcode == OP_CLOSE:
                return "close", _close_code_and_reason(payload)
            return ("ping" if opcode == OP_PING else "pong"), payload
        if self._fragments is None:
            if final:  # the usual case: a whole message in one frame
                if opcode == OP_BINARY:
                    return "binary", payload
                try:
                    return "text", payload.decode("utf-8")
                except UnicodeDecodeError:
                    raise ProtocolError(CLOSE_INVALID_PAYLOAD, "a text message must be UTF-8") from None
            self._fragments, self._fragment_bytes = [], 0
            # Text is checked fragment by fragment, so bad UTF-8 fails the connection at once.
            self._decoder = codecs.getincrementaldecoder("utf-8")() if opcode == OP_TEXT else None
        self._fragment_bytes += len(payload)
        if self._decoder is not None:
            try:
                self._fragments.append(self._decoder.decode(payload, final=bool(final)))
            except UnicodeDecodeError:
                raise ProtocolError(CLOSE_INVALID_PAYLOAD, "a text message must be UTF-8") from None
        else:
            self._fragments.append(payload)
        if not final:
            return None
        parts, self._fragments, self._fragment_bytes = self._fragments, None, 0
        if self._decoder is not None:
            return "text", "".join(parts)
        return "binary", b"".join(parts)
