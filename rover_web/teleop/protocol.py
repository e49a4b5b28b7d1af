"""What a teleop WebSocket frame may say, parsed strictly. Pure Python.

Client -> server, one JSON object per text frame:
  {"linear": f, "angular": f, "epoch": n, "source": "joystick"|"keyboard"|"gamepad", "seq": n, "t": ms}
                        drive; f in [-1, 1]
  {"stop": true, "seq": n}
                        the operator's own stop (stick released, key up, tab hidden); `seq`
                        (optional) numbers it among the drive frames, so that no drive frame sent
                        before it can act after it (the data channel does not keep order)
  {"takeover": true}    take control from whoever holds it
  {"release": true}     give control back
  {"estop": true}       engage the e-stop (any socket, driving or not): the page's fastest way to stop
  {"pong": n}           answers the data channel's {"type": "ping", "id": n} (a socket answers its
                        pings in WebSocket pong frames instead): the link's round trip
`epoch` (default 0) is the number from the server's latest "hello"/"state" message; `source`
defaults to "joystick". `seq` (a whole number that grows with every drive frame of the socket) and
`t` (the client's send time in milliseconds on any clock of its own that does not jump, such as
performance.now()) are optional: with them the server drops frames that come out of order and
measures the link (link.py); a client without them works as before.

Bad frames: a frame over the size limit closes the socket with 1009, a binary frame with 1003,
a frame that is not JSON at all with 1007. A JSON frame with wrong content (non-finite numbers,
strings, nulls, missing or unknown keys, values outside [-1, 1]) gets an error frame; the
connection stays open. Either way the caller stops the robot if this socket was driving it.
"""

from __future__ import annotations

from typing import NamedTuple

import orjson

from rover_web.web.api_messages import as_text, explain, text_of
from rover_web.web.validate import InvalidInput, json_type, loads_strict, number, only_keys, text

from .commands import SOURCES

CLOSE_UNSUPPORTED_DATA = 1003
CLOSE_INVALID_PAYLOAD = 1007
CLOSE_MESSAGE_TOO_BIG = 1009


class FrameError(Exception):
    """`close_code` None means: answer with an error frame and keep the socket."""

    def __init__(self, code: str, message: str, close_code: int | None = None):
        self.text = as_text(message, {})
        super().__init__(self.text.english())
        # `message` stays English: it is also a close frame's reason (at most 123 bytes, for logs).
        self.code, self.message, self.close_code = code, self.text.english(), close_code

    def as_frame(self, catalogues: tuple | None = None) -> dict:
        return {"type": "error", "error": self.code, "message": self.text.translated(catalogues), "status": 400}


class Drive(NamedTuple):  # a tuple: built 40 times a second, and cheaper than a frozen dataclass
    linear: float
    angular: float
    epoch: int = 0
    source: str = "joystick"
    seq: int | None = None
    t: float | None = None  # the client's send time, ms


class Control(NamedTuple):
    action: str  # stop | takeover | release | estop
    seq: int | None = None  # a stop's place among the socket's drive frames


class Pong(NamedTuple):
    id: int


CONTROL_ACTIONS = ("stop", "takeover", "release", "estop")
PING_ID_MAX = 2**32  # link.py numbers its pings in 4 bytes
DRIVE_KEYS = {"linear", "angular", "epoch", "source", "seq", "t"}
WHOLE_MAX = 2**53  # the largest whole number a browser's JSON numbers hold exactly


def _loads(data: str):
    """orjson first: cold, as a 40 Hz frame is, it decodes one in a third of the standard
    library's time (bench/teleop.py). Whatever it refuses, the strict standard decoder decodes or
    names the fault (non-finite numbers, bad syntax) as before. Where the two differ on what they
    accept, integers beyond 64 bits (orjson gives floats) and lone surrogates (orjson refuses),
    the frame's outcome cannot: no such value passes the checks below, and
    tests/unit/teleop/test_protocol.py compares both decoders on any frame."""
    try:
        return orjson.loads(data)
    except orjson.JSONDecodeError:
        return loads_strict(data)


def parse_frame(data: str | bytes, max_bytes: int) -> Drive | Control | Pong:
    if isinstance(data, (bytes, bytearray)):
        if len(data) > max_bytes:
            raise FrameError("frame_too_large", explain("frames are limited to %(max_bytes)s bytes",
                                                        max_bytes=max_bytes), CLOSE_MESSAGE_TOO_BIG)
        raise FrameError("binary_frame", explain("send JSON text frames, not binary"), CLOSE_UNSUPPORTED_DATA)
    # A character is at most 4 bytes in UTF-8: most frames need no encoding to be measured.
    if len(data) > max_bytes or (4 * len(data) > max_bytes
                                 and len(data.encode("utf-8", "surrogatepass")) > max_bytes):
        raise FrameError("frame_too_large", explain("frames are limited to %(max_bytes)s bytes",
                                                    max_bytes=max_bytes), CLOSE_MESSAGE_TOO_BIG)
    try:
        obj = _loads(data)
    except InvalidInput as exc:
        if exc.code == "non_finite":
            raise FrameError("non_finite", text_of(exc)) from None
        raise FrameError(
            "bad_json", explain("frame is not JSON: %(why)s", why=str(exc)[:120]), CLOSE_INVALID_PAYLOAD
        ) from None
    if not isinstance(obj, dict):
        raise FrameError("bad_frame", explain("a frame must be a JSON object, got %(json_type)s",
                                              json_type=json_type(obj)))
    try:
        for action in CONTROL_ACTIONS:
            if action in obj:
                only_keys(obj, {action, "seq"} if action == "stop" else {action})
                if obj[action] is not True:
                    raise InvalidInput("'%(action)s' must be true", "bad_value", action=action)
                return Control(action, _seq(obj) if "seq" in obj else None)
        if "pong" in obj:
            only_keys(obj, {"pong"})
            number_ = obj["pong"]
            if isinstance(number_, bool) or not isinstance(number_, int) or not 0 <= number_ < PING_ID_MAX:
                raise InvalidInput("'pong' must be the id of a ping, a whole number below %(ping_id_max)s", "bad_type",
                                   ping_id_max=PING_ID_MAX)
            return Pong(number_)
        only_keys(obj, DRIVE_KEYS)
        linear = number(obj, "linear", low=-1.0, high=1.0)
        angular = number(obj, "angular", low=-1.0, high=1.0)
        epoch = obj.get("epoch", 0)
        if isinstance(epoch, bool) or not isinstance(epoch, int) or not 0 <= epoch < WHOLE_MAX:
            raise InvalidInput("'epoch' must be a whole number from the server's last state message", "bad_type")
        source = text(obj, "source", default="joystick", choices=SOURCES)
        seq = _seq(obj) if "seq" in obj else None  # null included: absent is the way to send none
        t = None
        if "t" in obj:
            t = number(obj, "t", low=0.0, high=float(WHOLE_MAX))
    except InvalidInput as exc:
        raise FrameError(exc.code, text_of(exc)) from None
    return Drive(linear, angular, epoch, source, seq, t)


def _seq(obj: dict) -> int:
    seq = obj["seq"]
    if isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < WHOLE_MAX:
        raise InvalidInput("'seq' must be a whole number from 0 to %(value)s", "bad_type", value=WHOLE_MAX - 1)
    return seq
