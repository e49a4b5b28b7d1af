"""Teleop over a WebRTC data channel: the glue between a `teleop` channel and the TeleopController.

The browser opens the channel unordered with maxRetransmits 0, so a lost packet delays nothing
behind it: the next frame (40 Hz) carries the newest stick anyway. Everything else is the
WebSocket's: the same frames parsed and judged by the same `handle_frame` (websocket.py) and
controller (control.py): one holder, epochs, deadman, e-stop, re-arm; the same hello and `state`
frames back. Nothing here decides who may drive.

The link is measured as on the socket, every LINK_S: a channel has no ping frames of its own, so
the server sends `{"type": "ping", "id": n}` and the page answers `{"pong": n}` (the round trip,
link.py), then a `state` frame with the link's figures (`reason: "link"`), from which the Drive
card shows them and says when the link is too poor to drive.

Threads: aiortc calls `on_message` and `close` on its asyncio loop. A frame is judged on one
teleop thread (`handle`), not on the loop: an e-stop frame engages the latch, which writes the
database with an fsync, and the loop also carries every viewer's video. Replies and state frames
are sent from the loop (`call_soon`), where the channel lives. A closed channel or a failed peer
connection calls `close`, which zeroes the robot at once (controller.disconnect) if this channel
held control; frames still queued for the teleop thread are then refused as from a closed session.

Pure Python: the channel is anything with `send(str)`, `close()` and `readyState`.
"""

from __future__ import annotations

import json
import logging
import struct
from collections.abc import Callable
from concurrent.futures import Executor

from .control import Session, TeleopController
from .protocol import FrameError
from .websocket import LINK_S, handle_frame

log = logging.getLogger(__name__)

LABEL = "teleop"


class TeleopChannel:
    def __init__(self, channel, controller: TeleopController, name: str | None, hello: dict,
                 max_frame_bytes: int, *, call_soon: Callable[..., None], pool: Executor,
                 call_later: Callable[..., object] | None = None):
        self.channel = channel
        self.controller = controller
        self.max_frame_bytes = max_frame_bytes
        self._call_soon = call_soon
        self._pool = pool
        self.closed = False
        self.session: Session = controller.connect(name)
        self.session.wake = lambda: call_soon(self.flush)
        self.frames = 0
        self._call_later = call_later
        self._timer = None  # the next link report, while one is due (an asyncio.TimerHandle)
        self._reporting = False  # a link state is being made on the teleop thread
        self._send({**controller.session_state(self.session, "connected"), "type": "hello",
                    "session": self.session.id, "name": self.session.name, "transport": "datachannel", **hello})
        if call_later is not None:
            self._timer = call_later(LINK_S, self._link_tick)

    # --- on the loop ---

    def on_message(self, data) -> None:
        if self.closed:
            return
        self.frames += 1
        try:
            self._pool.submit(self.handle, data)
        except RuntimeError:  # the pool is shut down: the server is stopping
            self.close()

    def _link_tick(self) -> None:
        self._timer = None
        if self.closed:
            return
        self._send({"type": "ping", "id": struct.unpack("!I", self.session.link.ping())[0]})
        # The state is made on the teleop thread: it takes the controller's lock, which a frame
        # may hold, and the loop carries every viewer's video. One at a time, should that thread lag.
        if not self._reporting:
            self._reporting = True
            try:
                self._pool.submit(self._report_link)
            except RuntimeError:  # the pool is shut down: the server is stopping
                self.close()
                return
        self._timer = self._call_later(LINK_S, self._link_tick)

    def flush(self) -> None:
        outbox = self.session.outbox
        while outbox and not self.closed:
            self._send(outbox.popleft())

    def _send(self, message: dict) -> None:
        if getattr(self.channel, "readyState", "open") != "open":
            return
        try:
            self.channel.send(json.dumps(message, separators=(",", ":"), allow_nan=False))
        except Exception:  # the transport went away under us; `close` follows from aiortc
            log.debug("teleop data channel send failed", exc_info=True)

    def close(self) -> None:
        """The channel closed or its peer connection failed: zero now if it held control."""
        if self.closed:
            return
        self.closed = True
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self.session.wake = None
        self.controller.disconnect(self.session)

    # --- on the teleop thread ---

    def handle(self, data) -> None:
        if self.closed:
            return
        try:
            reply = handle_frame(self.controller, self.session, data, self.max_frame_bytes)
        except FrameError as exc:  # a frame a socket would be closed for: stop, say why, close the channel
            self.controller.disconnect(self.session)
            self._call_soon(self._end, exc.as_frame(self.session.catalogues))
            return
        except Exception:
            log.exception("teleop frame from a data channel failed; closing the channel")
            self.controller.disconnect(self.session)
            self._call_soon(self._end, {"type": "error", "error": "internal_error", "message": "internal error",
                                        "status": 500})
            return
        if reply is not None:
            self.session.outbox.append(reply)
            self._call_soon(self.flush)

    def _report_link(self) -> None:
        self._reporting = False
        if self.closed:
            return
        self.session.outbox.append(self.controller.session_state(self.session, "link"))
        self._call_soon(self.flush)

    def _end(self, message: dict) -> None:
        self._send(message)
        self.close()
        try:
            self.channel.close()
        except Exception:
            log.debug("closing a teleop data channel failed", exc_info=True)
