"""The teleop WebSocket: frames are handled in the socket's reader thread, replies sent by its own.

flask-sock's usual loop (`ws.receive()` in the request thread) costs every frame a hand-off: the
reader thread parses it, sets an event, and the request thread wakes to act on it. On a virtual
machine that wake-up is most of the gap between a joystick frame and the Twist on the wire
(bench/teleop.py). simple_websocket lets the app supply that event (`event_class`); ours, on
`set()`, handles every complete frame at once in the reader thread, so a joystick input is
published the moment it has been read, and a closed socket stops the robot from the thread that
saw it close. The request thread keeps what may block or must not interleave: every `send()`
(hello, state changes, error replies, pings) and the close handshake.

The pings are ours too, sent from the request thread: given `ping_interval`, simple_websocket's
reader waits in a Python selector loop before every read, which measured 40 µs (median) more per
frame than its plain blocking read. The rule is the library's: a ping every `ping_s`, and a
client that has not answered by the next one loses the socket (1008) and control.
"""

from __future__ import annotations

import json
import logging
import math
import socket
import threading
import time
from typing import Callable

from flask_sock import ConnectionClosed
from wsproto.events import Ping
from wsproto.utilities import LocalProtocolError

from .teleop_control import Refused, Session, TeleopController
from .teleop_protocol import Control, Drive, FrameError, parse_frame

log = logging.getLogger(__name__)

CLOSE_POLICY_VIOLATION = 1008
CLOSE_INTERNAL_ERROR = 1011
# How often the request thread, with nothing to send, checks for shutdown.
POLL_S = 0.05
# How long a client has to answer our close frame before the connection is cut.
CLOSE_GRACE_S = 0.5


class InlineFrames:
    """simple_websocket's `event_class`. The reader thread calls `set()` after each complete
    message and when the connection ends; once `attach()`ed, `set()` first runs the handler there
    (one at a time, in arrival order). `wait()`/`clear()` wake the request thread as before."""

    def __init__(self) -> None:
        self._wake = threading.Event()
        self._handling = threading.Lock()
        self._handler: Callable[[], None] | None = None

    def attach(self, handler: Callable[[], None]) -> None:
        """From now on `set()` calls `handler`; it runs once now for anything that came before."""
        self._handler = handler
        self.set()

    def set(self) -> None:
        handler = self._handler
        if handler is not None:
            with self._handling:
                handler()
        self._wake.set()

    def wake(self) -> None:
        self._wake.set()

    def wait(self, timeout: float | None = None) -> bool:
        return self._wake.wait(timeout)

    def clear(self) -> None:
        self._wake.clear()

    def is_set(self) -> bool:
        return self._wake.is_set()


def handle_frame(controller: TeleopController, session: Session, data, max_bytes: int) -> dict | None:
    """One frame in; an error frame to answer with, or None. FrameError with a close code escapes."""
    try:
        frame = parse_frame(data, max_bytes)
    except FrameError as exc:
        controller.stop(session, "bad_input")  # zero if this socket was driving; ignored for viewers
        if exc.close_code is not None:
            raise
        return exc.as_frame()
    try:
        if isinstance(frame, Drive):
            controller.drive(session, frame.linear, frame.angular, epoch=frame.epoch, source=frame.source)
        elif isinstance(frame, Control) and frame.action == "stop":
            controller.stop(session, "operator")
        elif frame.action == "takeover":
            controller.takeover(session)
        elif frame.action == "release":
            controller.release(session)
    except Refused as exc:
        return exc.as_frame()
    return None


def send(ws, message: dict) -> None:
    ws.send(json.dumps(message, separators=(",", ":"), allow_nan=False))


class TeleopSocket:
    """One accepted /ws/teleop connection (`ws` built with `event_class=InlineFrames`)."""

    def __init__(self, ws, controller: TeleopController, session: Session, max_frame_bytes: int):
        self.ws = ws
        self.controller = controller
        self.session = session
        self.max_frame_bytes = max_frame_bytes
        self.events: InlineFrames = ws.event
        self._close: tuple[int, str] | None = None  # set by the reader thread, carried out by ours
        session.wake = self.events.wake

    def serve(self, hello: dict, stopping: threading.Event, ping_s: float | None = None) -> None:
        """Runs in the request thread until the socket ends or the server stops."""
        ws, session = self.ws, self.session
        next_ping = time.monotonic() + ping_s if ping_s else math.inf
        try:
            send(ws, hello)
            self.events.attach(self._on_reader_event)
            while not stopping.is_set():
                self.events.wait(max(0.0, min(POLL_S, next_ping - time.monotonic())))
                self.events.clear()
                while session.outbox:
                    send(ws, session.outbox.popleft())
                if self._close is not None:
                    self._hang_up(*self._close)
                    return
                if not ws.connected:
                    return
                if time.monotonic() >= next_ping:
                    if not ws.pong_received:
                        self.controller.disconnect(session)  # zero before the close frame goes out
                        self._hang_up(CLOSE_POLICY_VIOLATION, "Ping/Pong timeout")
                        return
                    self._ping()
                    next_ping = time.monotonic() + ping_s
            self._hang_up(1001, "server shutting down")
        except ConnectionClosed:
            pass
        finally:
            self.controller.disconnect(session)

    def _hang_up(self, code: int, message: str) -> None:
        """Send our close frame, give the client CLOSE_GRACE_S to answer it (its answer ends the
        reader thread), then cut the connection: the reader waits in a blocking read, and a client
        that is gone or ignores the close must not keep it, and the socket, forever."""
        ws = self.ws
        ws.close(reason=code, message=message)
        reader = getattr(ws, "thread", None)
        if reader is not None and reader is not threading.current_thread():
            reader.join(CLOSE_GRACE_S)
            if not reader.is_alive():
                return
        try:
            ws.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass  # already gone

    def _ping(self) -> None:
        """What simple_websocket's reader does when it pings, done here so the reader never has to
        time anything; the reader still records the pong (`pong_received`)."""
        ws = self.ws
        ws.pong_received = False
        try:
            ws.sock.send(ws.ws.send(Ping()))
        except (OSError, LocalProtocolError):
            raise ConnectionClosed(ws.close_reason, ws.close_message) from None

    def _on_reader_event(self) -> None:
        """In the reader thread: a frame arrived, or the connection ended. Must never raise: an
        exception here would end the reader thread with the socket still open."""
        ws = self.ws
        try:
            while ws.input_buffer and self._close is None:
                data = ws.input_buffer.pop(0)
                try:
                    reply = handle_frame(self.controller, self.session, data, self.max_frame_bytes)
                except FrameError as exc:
                    self._ending((exc.close_code, exc.message[:120]))
                    return
                if reply is not None:
                    self.session.outbox.append(reply)
            if not ws.connected:
                self.controller.disconnect(self.session)  # zero now, not when our thread next wakes
        except Exception:
            log.exception("teleop frame handling failed; closing the socket")
            self._ending((CLOSE_INTERNAL_ERROR, "internal error"))

    def _ending(self, close: tuple[int, str]) -> None:
        self._close = close
        self.ws.input_buffer.clear()
        try:
            self.controller.disconnect(self.session)  # zero before the close frame goes out
        except Exception:  # pragma: no cover - a bug; the request thread's `finally` tries again
            log.exception("teleop disconnect failed")
