"""The teleop WebSocket after its handshake: our reader thread turns each frame into a Twist at
once; the request thread does the rest.

flask-sock routes /ws/teleop and simple_websocket does the handshake, then starts one thread per
connection to read it (`thread_class`). Ours, `FrameReader`, reads with ws_frames.FrameParser
instead of the library's wsproto loop, and handles each joystick frame in that same thread: read,
parsed, published, with no hand-off to another thread and no library layers in between. On this
machine that path runs cold for every 40 Hz frame, and each layer removed showed in
bench/teleop.py (BENCHMARKS.md). A socket that closes or breaks is stopped from the thread that
saw it.

The request thread (`TeleopSocket.serve`) keeps what may wait: every message to the client (hello,
state changes, error replies), the pings, and the close handshake. A client that has not
answered one ping by the next loses the socket (1008) and control. Every LINK_S it also sends a
ping carrying an id, whose pong gives the round trip (link.py), and a `state` frame with the
link's figures (`reason: "link"`), so the page shows the link even while nothing changes.

No extension is agreed (routes.py drops the offer before the handshake): permessage-deflate on
~50-byte frames saves nothing and costs both ends zlib work on every frame.
"""

from __future__ import annotations

import json
import logging
import math
import socket
import struct
import threading
import time

from rover_web.web.api_messages import explain

from .control import Refused, Session, TeleopController
from .protocol import Control, Drive, FrameError, Pong, parse_frame
from .ws_frames import (
    CLOSE_NO_STATUS,
    CLOSE_NORMAL,
    OP_PING,
    OP_PONG,
    FrameParser,
    ProtocolError,
    close_frame,
    frame,
    text_frame,
)

log = logging.getLogger(__name__)

CLOSE_GOING_AWAY = 1001
CLOSE_POLICY_VIOLATION = 1008
CLOSE_INTERNAL_ERROR = 1011
RECEIVE_BYTES = 4096
# How often the request thread, with nothing to send, checks for shutdown.
POLL_S = 0.05
# How long a client has to answer our close frame before the connection is cut.
CLOSE_GRACE_S = 0.5
# How often a socket gets a measuring ping and a `state` frame with its link's figures.
LINK_S = 0.5


class FrameReader(threading.Thread):
    """simple_websocket's `thread_class`. The library builds one per connection with its own read
    loop as `target` and starts it; this thread runs `TeleopSocket.read_frames` instead, once the
    route has attached one. Until then frames wait in the kernel's socket buffer."""

    def __init__(self, target, **_ignored):
        server = getattr(target, "__self__", None)  # the simple_websocket.Server being started
        if getattr(server, "sock", None) is None:
            raise TypeError("FrameReader reads a simple_websocket connection; it was given " + repr(target))
        super().__init__(name="teleop-reader", daemon=True)
        self.server = server
        self._attached = threading.Event()
        self._teleop: TeleopSocket | None = None

    def attach(self, teleop: TeleopSocket | None) -> None:
        """Start reading for `teleop`; None (or a second call) lets an unused reader end."""
        if not self._attached.is_set():
            self._teleop = teleop
            self._attached.set()

    def run(self) -> None:
        self._attached.wait()
        if self._teleop is not None:
            self._teleop.read_frames()


def handle_frame(controller: TeleopController, session: Session, data, max_bytes: int) -> dict | None:
    """One frame in; an error frame to answer with, or None. FrameError with a close code escapes."""
    try:
        frame_ = parse_frame(data, max_bytes)
    except FrameError as exc:
        controller.stop(session, "bad_input")  # zero if this socket was driving; ignored for viewers
        if exc.close_code is not None:
            raise
        return exc.as_frame(session.catalogues)
    try:
        if isinstance(frame_, Drive):
            controller.drive(session, frame_.linear, frame_.angular, epoch=frame_.epoch, source=frame_.source,
                             seq=frame_.seq, sent_ms=frame_.t)
        elif isinstance(frame_, Pong):
            session.link.pong(struct.pack("!I", frame_.id))
        elif isinstance(frame_, Control) and frame_.action == "stop":
            controller.stop(session, "operator", seq=frame_.seq)
        elif frame_.action == "takeover":
            controller.takeover(session)
        elif frame_.action == "release":
            controller.release(session)
        elif frame_.action == "estop":
            if controller.request_estop is None:
                raise Refused("no_estop", explain("this server has no e-stop to engage"), status=501)
            controller.request_estop(session.name)  # the engage hook tells every socket, this one too
    except Refused as exc:
        return exc.as_frame(session.catalogues)
    return None


class TeleopSocket:
    """One accepted /ws/teleop connection: `ws` is the simple_websocket.Server that flask-sock
    built with `thread_class=FrameReader`; after the handshake only its socket is used."""

    def __init__(self, ws, controller: TeleopController, session: Session, max_frame_bytes: int):
        self.ws = ws
        self.sock: socket.socket = ws.sock
        self.reader: FrameReader = ws.thread
        self.controller = controller
        self.session = session
        self.max_frame_bytes = max_frame_bytes
        self.pong_received = True
        self._wake = threading.Event()
        self._send_lock = threading.Lock()
        self._close_sent = False
        self._close: tuple[int, str] | None = None  # asked for by the reader, carried out by serve()
        self._reader_done = False
        session.wake = self._wake.set

    # --- the request thread ---

    def serve(self, hello: dict, stopping: threading.Event, ping_s: float | None = None,
              link_s: float | None = LINK_S) -> None:
        """Runs in the request thread until the socket ends or the server stops."""
        session = self.session
        next_ping = time.monotonic() + ping_s if ping_s else math.inf
        next_link = time.monotonic() if link_s else math.inf
        try:
            self._send(hello)
            self.reader.attach(self)
            while not stopping.is_set():
                self._wake.wait(max(0.0, min(POLL_S, next_ping - time.monotonic(), next_link - time.monotonic())))
                self._wake.clear()
                if time.monotonic() >= next_link and not self._close_sent:
                    self._write(frame(OP_PING, session.link.ping()))
                    session.outbox.append(self.controller.session_state(session, "link"))
                    next_link = time.monotonic() + link_s
                while session.outbox and not self._close_sent:
                    self._send(session.outbox.popleft())
                if self._close is not None:
                    self._hang_up(*self._close)
                    return
                if self._reader_done:
                    return
                if time.monotonic() >= next_ping:
                    if not self.pong_received:
                        self.controller.disconnect(session)  # zero before the close frame goes out
                        self._hang_up(CLOSE_POLICY_VIOLATION, "Ping/Pong timeout")
                        return
                    self.pong_received = False
                    self._write(frame(OP_PING))
                    next_ping = time.monotonic() + ping_s
            self._hang_up(CLOSE_GOING_AWAY, "server shutting down")
        except OSError:
            pass  # the peer is gone; the reader sees it too
        finally:
            self.reader.attach(None)  # if we never got as far as attaching, the reader ends now
            self.controller.disconnect(session)
            self._cut_if_still_reading(0.0)
            self.ws.connected = False  # so flask-sock's own close() afterwards does nothing

    def _send(self, message: dict) -> None:
        self._write(text_frame(json.dumps(message, separators=(",", ":"), allow_nan=False)))

    def _write(self, data: bytes) -> None:
        with self._send_lock:
            self.sock.sendall(data)

    def _send_close(self, code: int, reason: str) -> None:
        """Our close frame, at most once, whichever side began the closing handshake."""
        with self._send_lock:
            if self._close_sent:
                return
            self._close_sent = True
            try:
                self.sock.sendall(close_frame(code, reason))
                # Nothing may follow a close frame, so end our side now: the client sees the
                # close, then the end of the stream, and answers at once (RFC 6455 7.1.1).
                self.sock.shutdown(socket.SHUT_WR)
            except OSError:
                pass  # gone already; nothing left to tell it

    def _hang_up(self, code: int, reason: str) -> None:
        """Send our close frame and give the client CLOSE_GRACE_S to answer it (its answer ends the
        reader); then cut the connection, so a client that is gone or ignores the close keeps
        neither the reader thread nor the socket."""
        self._send_close(code, reason)
        self._cut_if_still_reading(CLOSE_GRACE_S)

    def _cut_if_still_reading(self, grace_s: float) -> None:
        reader = self.reader
        if reader is threading.current_thread() or not reader.is_alive():
            return
        if grace_s:
            reader.join(grace_s)
            if not reader.is_alive():
                return
        try:
            self.sock.shutdown(socket.SHUT_RDWR)  # wakes the reader's blocking recv()
        except OSError:
            pass  # already gone
        reader.join(CLOSE_GRACE_S)

    # --- the reader thread ---

    def read_frames(self) -> None:
        """Until the peer closes or the connection fails. Must never raise: the robot has to be
        stopped however the reading ends."""
        parser = FrameParser(self.max_frame_bytes)
        recv = self.sock.recv
        try:
            while True:
                data = recv(RECEIVE_BYTES)
                if not data:
                    return
                try:
                    events = parser.feed(data)
                except ProtocolError as exc:
                    self._ending(exc.close_code, exc.message)
                    while recv(RECEIVE_BYTES):  # nothing more can be parsed; wait for the client to go
                        pass
                    return
                for kind, body in events:
                    if kind == "text" or kind == "binary":
                        self._on_message(body)
                    elif kind == "ping":
                        self._write(frame(OP_PONG, body))
                    elif kind == "pong":
                        if body:  # the answer to a measuring ping (LINK_S); the empty ones keep us alive
                            self.session.link.pong(body)
                        else:
                            self.pong_received = True
                    else:  # close: answer it (unless it answers ours) and stop reading
                        code = body[0]
                        self._send_close(CLOSE_NORMAL if code == CLOSE_NO_STATUS else code, "")
                        return
        except OSError:
            pass  # reset, or shut down by _cut_if_still_reading
        except Exception:
            log.exception("teleop socket reader failed; closing the socket")
            self._ending(CLOSE_INTERNAL_ERROR, "internal error")
        finally:
            self._reader_done = True
            try:
                self.controller.disconnect(self.session)  # zero now, not when the request thread wakes
            finally:
                self._wake.set()

    def _on_message(self, data) -> None:
        if self._close is not None:
            return  # closing: nothing the client says now may move the robot
        try:
            reply = handle_frame(self.controller, self.session, data, self.max_frame_bytes)
        except FrameError as exc:
            self._ending(exc.close_code, exc.message[:120])
            return
        except Exception:
            log.exception("teleop frame handling failed; closing the socket")
            self._ending(CLOSE_INTERNAL_ERROR, "internal error")
            return
        if reply is not None:
            self.session.outbox.append(reply)
            self._wake.set()

    def revoke(self, reason: str) -> None:
        """Its user's credentials ended (rover_web/auth/revocation.py): stop the robot, close with 1008."""
        self._ending(CLOSE_POLICY_VIOLATION, reason[:120])

    def _ending(self, code: int, reason: str) -> None:
        """Stop the robot, then have the request thread close the socket with `code`."""
        try:
            self.controller.disconnect(self.session)  # zero before the close frame goes out
        except Exception:  # pragma: no cover - a bug; the request thread's `finally` tries again
            log.exception("teleop disconnect failed")
        self._close = (code, reason)
        self._wake.set()
