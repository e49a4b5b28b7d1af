"""The teleop controller: deadman with hold and ramp, e-stop latch, control ownership, the held command.

Pure Python (no Flask, no rclpy). The output is anything with `send(linear_mps, angular_rps)` and
`zero()` (rover.cmd_vel in the app) and the clocks are injectable, so every rule below is
unit-tested with a fake clock and a recording output. Its parts live beside it: commands.py
(scaling, clamps, the command held, refusals), sessions.py (sockets and who holds control),
ramp.py (what a command is worth as its input ages), link.py (each socket's link), repeater.py
(the thread that calls tick()).

Rules, all enforced under one lock so no two threads can interleave a stale command after a stop:

- A joystick/keyboard input is published at once from the thread that received it; the held
  command is then repeated every 1/rate_hz by one repeater thread (`Repeater`), never by browsers.
- Deadman, in three steps (ramp.py): with no fresh input for up to `deadman_s` the last command is
  held as it was; then the published speed ramps linearly down to zero, reaching it at `deadman_max_s`,
  the hard bound, when one zero is published and the command ends. A fresh input during the
  hold or the ramp (same epoch, newer `seq`) takes over at once, with no stop and no new epoch, so a
  stall that ends does not force a re-arm. A frame's freshness dates from when it was sent
  (link.py's lateness), not when it came: a frame that waited in a stalled buffer extends nothing.
  The check also runs lazily before every input, so a server that was itself stalled stops first
  and only then looks at the frames that piled up.
- Order: a frame whose `seq` is not newer than one already seen from its socket is dropped, so
  a late frame never overrides a newer one. A stop counts: one with a `seq` fences off every
  drive frame numbered below it (sent before it, delivered after it over the unordered data
  channel), and is itself ignored if a newer frame was admitted first.
- Epochs: every socket session has an epoch, starting at 0, that its motion frames must echo.
  A stop the operator did not ask for (deadman, e-stop, takeover, REST stop) bumps the epoch and
  tells the session. Frames sent before the client heard of the stop carry the old epoch and are
  dropped, so frames queued during a stall can never restart the robot; motion resumes only on a
  frame sent after the server's stop notice reached the client, i.e. from a live operator.
- One operator at a time (sessions.py). Disconnecting, releasing, a bad frame, the operator's own
  stop: zero at once, no hold, no ramp.
- E-stop: a latch. While engaged only zero is published and every motion request is refused (409).
- REST commands run for a bounded duration (their own deadman, no ramp) and only while nobody
  holds control; a REST `stop` always wins.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import Counter
from collections.abc import Callable

from rover_web.web.api_messages import explain

from .commands import REST_COMMANDS, Command, Limits, Refused, scale
from .ramp import Ramp
from .sessions import Session, Sessions

log = logging.getLogger(__name__)

# After a fresh input the first repeat waits a little longer than one period. An input stream at
# about the repeat rate (a client sending at rate_hz) would otherwise race the repeater at every
# frame: the repeat of the old value goes out just before each new one, doubling the rate and,
# holding the lock, delaying the new value (bench/teleop.py sends on a 40 Hz grid).
INPUT_REPEAT_DELAY = 1.2


class TeleopController:
    def __init__(self, output, limits: Limits, *, rate_hz: float = 40.0, deadman_s: float = 0.3,
                 deadman_max_s: float | None = None,
                 clock: Callable[[], float] = time.monotonic, wall_clock: Callable[[], float] = time.time,
                 on_state: Callable[[dict], None] | None = None, estop: dict | None = None,
                 request_estop: Callable[[str], object] | None = None):
        self._cond = threading.Condition(threading.RLock())
        self._output = output
        self.limits = limits
        self.rate_hz = rate_hz
        self.period_s = 1.0 / rate_hz
        self.deadman_s = deadman_s
        # The hard bound is never shorter than the hold: a smaller one means hold, then stop.
        self.deadman_max_s = max(deadman_s, deadman_max_s if deadman_max_s is not None else deadman_s)
        self.ramp = Ramp(deadman_s, self.deadman_max_s)
        self._clock = clock
        self._wall = wall_clock
        self._on_state = on_state
        self.request_estop = request_estop  # a socket's {"estop": true}: engages the app's e-stop
        self.audit = None  # the robot's AuditHub (events/audit.py), set by teleop.init_app: who held control
        self._sessions = Sessions(clock)
        self._holder: Session | None = None  # holds control (sessions.py); a plain attribute: read on every frame
        self._command: Command | None = None
        self._next_tick = math.inf
        self._ramping = False  # the last value published was the held command ramped down
        self._estop = {"engaged": False, "since": None, "by": None}
        if estop:
            self._estop.update({k: estop[k] for k in ("engaged", "since", "by") if k in estop})
        self._last_stop: dict | None = None
        self._closed = False
        self._shown: dict | None = None
        self.stats: Counter = Counter()

    # --- sessions and control ---

    def connect(self, name: str | None = None) -> Session:
        with self._cond:
            session = self._sessions.open(name)
            self._audit("teleop.session_open", session)
            self._changed()
            return session

    def disconnect(self, session: Session) -> None:
        """The socket closed or failed: if it held control, zero at once and free control."""
        with self._cond:
            self._expire(self._clock())
            if not self._sessions.close(session):
                return
            if self._holder is session:
                self._holder = None
                self._stop("disconnected")
                self._audit("teleop.control_end", session, reason="disconnected")
            self._audit("teleop.session_close", session)
            self._changed()

    def takeover(self, session: Session) -> None:
        """Explicitly take control (or claim it when free). Whatever was moving stops first."""
        with self._cond:
            self._expire(self._clock())
            self._require_open(session)
            if self._holder is session:
                return
            if self._estop["engaged"]:
                raise Refused("estop_engaged", explain("the e-stop is engaged: nobody takes control until it is "
                                                       "released"))
            previous = self._holder
            self._holder = session
            self._audit("teleop.takeover", session, previous=previous.name if previous else None)
            if self._command is not None:
                self._stop("taken_over")
            if previous is not None:
                previous.epoch += 1  # frames it still had in flight are stale
                self._tell(previous, "taken_over")
            self._tell(session, "in_control")
            self._changed()

    def release(self, session: Session) -> None:
        """The holder gives control back; the robot stops."""
        with self._cond:
            self._expire(self._clock())
            if self._holder is not session:
                return
            self._holder = None
            self._stop("released")
            self._audit("teleop.control_end", session, reason="released")
            self._tell(session, "released")
            self._changed()

    # --- motion ---

    def drive(self, session: Session, linear: float, angular: float, *, epoch: int = 0,
              source: str = "joystick", seq: int | None = None, sent_ms: float | None = None) -> tuple[float, float]:
        """A joystick/keyboard/gamepad input (fractions of the maxima). Published at once if it changed.

        `seq` and `sent_ms` (the client's send time, on its own millisecond clock) are optional:
        without them a frame is in order and as fresh as its arrival."""
        now = None
        try:
            with self._cond:
                now = self._clock()
                self._expire(now)  # a stalled server stops first, then judges the frames that piled up
                self._require_open(session)
                late_s = session.link.admit(seq, sent_ms, now)  # the meter has this controller's clock
                if late_s is None:
                    now = None  # dropped, and not measured either
                    self.stats["out_of_order_dropped"] += 1
                    raise Refused("stale_seq", explain("frame %(seq)s dropped: a newer frame from this socket came "
                                                       "first", seq=seq))
                command = self._drive(session, linear, angular, epoch, late_s, now)
                new_source = source != session.source  # logged once per change, not per frame
                session.source = source
                command.source = source
                self._changed()
                self._cond.notify_all()
        finally:
            # After the publish and outside the lock: measuring never delays a command, and
            # frames refused for their content or their epoch still tell of the link.
            if now is not None:
                session.link.record(sent_ms, now)
        if new_source:  # the log's I/O never delays a command either
            log.info("teleop: %s drives with the %s", session.name, source)
        return command.linear_mps, command.angular_rps

    def _drive(self, session: Session, linear: float, angular: float, epoch: int, late_s: float,
               now: float) -> Command:
        """The rules for an admitted drive frame, with the lock held: the command it sets (published
        at once if it changed), or Refused."""
        if self._estop["engaged"]:
            raise Refused("estop_engaged", explain("the e-stop is engaged: release it (POST /api/estop {\"engaged\": "
                                                   "false}) before driving"))
        if not session.armed:
            if linear or angular:
                raise Refused("rearm_required", explain("the robot was stopped (%(last_stop_reason)s) while this "
                                                        "input was held: release the stick (or key) to re-arm, "
                                                        "then drive",
                                                        last_stop_reason=self._last_stop_reason()))
            session.armed = True
        if epoch != session.epoch:
            self.stats["stale_dropped"] += 1
            raise Refused("stale_epoch", explain("frame for epoch %(epoch)s dropped: the robot was stopped "
                                                 "(%(last_stop_reason)s); send epoch %(epoch2)s to drive again",
                                                 epoch=epoch, last_stop_reason=self._last_stop_reason(),
                                                 epoch2=session.epoch), epoch=session.epoch)
        if late_s >= self.deadman_max_s:  # its input is past the bound already (ramp.expired)
            self.stats["late_dropped"] += 1
            raise Refused("late_frame", explain("frame dropped: it arrived %(value)s ms late, past the %(value2)s ms "
                                                "any input may drive for", value=format(1000 * late_s, ".0f"),
                                                value2=format(1000 * self.deadman_max_s, ".0f")))
        if self._holder is None:
            self._holder = session
            self._audit("teleop.control_start", session)
            self._tell(session, "in_control")
        elif self._holder is not session:
            raise Refused("not_in_control", explain("%(name)s holds control; you are view-only until they release "
                                                    "it or you send {\"takeover\": true}",
                                                    name=self._holder.name),
                          holder=self._holder.public())
        linear_mps, angular_rps = scale(linear, angular, self.limits)
        previous = self._command
        fresh_at = now - late_s
        self._command = command = Command(linear_mps, angular_rps, "", session, fresh_at,
                                          fresh_at + self.deadman_max_s)
        if late_s > self.deadman_s:  # came in so late that its own value is already easing off
            self._publish_command(now)
            self._next_tick = now + self.period_s * INPUT_REPEAT_DELAY
        elif (previous is None or previous.session is not session or self._ramping
                or (previous.linear_mps, previous.angular_rps) != (linear_mps, angular_rps)):
            self._ramping = False
            self._publish(linear_mps, angular_rps)
            self._next_tick = now + self.period_s * INPUT_REPEAT_DELAY
        self.stats["inputs"] += 1
        return command

    def stop(self, session: Session, reason: str = "operator", seq: int | None = None) -> bool:
        """The holder's own stop (stick released, key up, tab hidden). A viewer's stop is ignored,
        and so is a stop whose `seq` is older than a frame already admitted (link.fence)."""
        with self._cond:
            if not session.link.fence(seq):
                self.stats["stale_stops_dropped"] += 1
                return False
            self._expire(self._clock())
            session.armed = True  # a stop is the neutral input that re-arms after an e-stop
            session.link.idle()
            if self._holder is not None and self._holder is not session:
                return False
            self._stop(reason)
            self._changed()
            return True

    def rest_command(self, command: str, speed: float, duration_s: float,
                     owner: object = None) -> tuple[float, float]:
        """POST /api/teleop: drive for `duration_s`, then stop by itself (or by `end_rest(owner)`)."""
        with self._cond:
            now = self._clock()
            self._expire(now)
            if self._closed:
                raise Refused("shutting_down", explain("the server is shutting down"), status=503)
            if self._estop["engaged"]:
                raise Refused("estop_engaged", explain("the e-stop is engaged: release it (POST /api/estop "
                                                       "{\"engaged\": false}) before driving"))
            if self._holder is not None:
                raise Refused("not_in_control", explain("%(name)s holds control with the joystick; REST commands "
                                                        "run only while nobody holds it (stop always works)",
                                                        name=self._holder.name),
                              holder=self._holder.public())
            direction = REST_COMMANDS[command]
            linear_mps, angular_rps = scale(direction[0] * speed, direction[1] * speed, self.limits)
            self._command = Command(linear_mps, angular_rps, "rest", None, now, now + duration_s, owner)
            self._publish_command(now)
            self._next_tick = now + self.period_s
            self._changed()
            self._cond.notify_all()
            return linear_mps, angular_rps

    def rest_stop(self) -> None:
        """POST /api/teleop stop: always wins. The holder must send a fresh input to move again."""
        with self._cond:
            self._expire(self._clock())
            self._stop("rest_stop", bump=[self._holder] if self._holder else (), always=True)
            self._changed()

    def end_rest(self, owner: object, reason: str) -> bool:
        """Stop the REST command under way if `owner` started it (its credential ended); False if
        another command, or none, is held: someone else's drive goes on."""
        with self._cond:
            command = self._command
            if owner is None or command is None or command.session is not None or command.owner is not owner:
                return False
            self._stop(reason)
            self._changed()
            return True

    # --- e-stop latch ---

    @property
    def estop(self) -> dict:
        with self._cond:
            return dict(self._estop)

    def engage_estop(self, by: str) -> dict:
        """Zero at once and refuse motion until released. Works whoever holds control."""
        with self._cond:
            if not self._estop["engaged"]:
                self._estop = {"engaged": True, "since": self._wall(), "by": by}
            self._stop("estop", bump=list(self._sessions), always=True)
            self._changed()
            return dict(self._estop)

    def link_lost(self) -> None:
        """The robot's link went stale: stop what is held, and make every socket return to neutral
        before it drives again (as after an e-stop), so a robot that comes back does not take up a
        command the operator gave before it vanished."""
        with self._cond:
            held = self._command is not None
            for session in self._sessions:
                session.armed = False
            self.stats["link_stops"] += 1  # for /metrics (rover_web/metrics)
            self._stop("link_lost", bump=list(self._sessions))
            if held:
                self._changed()

    def release_estop(self, by: str) -> dict:
        with self._cond:
            if self._estop["engaged"]:
                self._estop = {"engaged": False, "since": self._wall(), "by": by}
                for session in self._sessions:
                    session.armed = False
                    self._tell(session, "estop_released")
                self._changed()
            return dict(self._estop)

    # --- the repeater's side ---

    def tick(self) -> float | None:
        """Enforce deadlines and repeat the held command (ramped, if its input is going stale) when
        due; the next wake-up time or None."""
        with self._cond:
            now = self._clock()
            self._expire(now)
            command = self._command
            if command is None:
                return None
            if now >= self._next_tick:
                ramping = self._ramping
                self._publish_command(now)
                self.stats["repeated"] += 1
                self._next_tick += self.period_s  # a fixed grid: late wake-ups do not lower the rate
                if self._next_tick <= now:
                    self._next_tick = now + self.period_s
                if ramping != self._ramping:
                    self._changed()
            return min(self._next_tick, command.expires_at)

    def close(self) -> None:
        """Shutdown: nothing is published after this, and the repeater exits."""
        with self._cond:
            self._command = None
            self._closed = True
            self._cond.notify_all()

    @property
    def closed(self) -> bool:
        return self._closed

    # --- state for pages ---

    def state(self) -> dict:
        with self._cond:
            return self._state()

    def session_state(self, session: Session, reason: str = "") -> dict:
        with self._cond:
            return self._session_message(session, reason)

    # --- internals (called with the lock held) ---

    def _audit(self, action: str, session: Session, **metadata) -> None:
        if self.audit is not None:
            self.audit.record(action, by=session.name, detail=f"{action.split('.')[1].replace('_', ' ')}: "
                              f"{session.name}", session=session.id, **metadata)

    def _require_open(self, session: Session) -> None:
        if self._closed:
            raise Refused("shutting_down", explain("the server is shutting down"), status=503)
        if not self._sessions.is_open(session):
            raise Refused("disconnected", explain("this session is closed; reconnect"), status=410)

    def _expire(self, now: float) -> None:
        command = self._command
        if command is None or now < command.expires_at:
            return
        if command.session is None:
            self._stop("duration_elapsed")
        else:
            self.stats["deadman_stops"] += 1
            self._stop("deadman", bump=[command.session])
        self._changed()

    def _stop(self, reason: str, bump=(), always: bool = False) -> None:
        """End the held command with one zero. With nothing held, only an explicit stop (REST stop,
        e-stop) publishes: an idle page closing must not send zeros that would, say, interrupt
        an autonomous goal the robot is following."""
        if self._command is not None or always:
            self._publish_zero()
            self._last_stop = {"reason": reason, "at": round(self._wall(), 3)}
        self._command = None
        self._ramping = False
        self._next_tick = math.inf
        for session in bump:
            if session is not None:
                session.epoch += 1
                self._tell(session, reason)
        self._cond.notify_all()

    def _tell(self, session: Session, reason: str) -> None:
        session.outbox.append(self._session_message(session, reason))
        if session.wake is not None:
            session.wake()

    def _session_message(self, session: Session, reason: str) -> dict:
        holder = self._holder
        return {"type": "state", "epoch": session.epoch, "in_control": holder is session,
                "holder": holder.public() if holder else None, "estop": self._estop["engaged"],
                "armed": session.armed, "reason": reason, "link": session.link.snapshot()}

    def _publish_command(self, now: float) -> None:
        """The held command as it stands now: a REST command as given, a socket's ramped by age."""
        command = self._command
        if command.session is None:
            self._ramping = False
            self._publish(command.linear_mps, command.angular_rps)
            return
        factor = self.ramp.factor(now - command.fresh_at)
        self._ramping = factor < 1.0
        self._publish(command.linear_mps * factor, command.angular_rps * factor)

    def _publish(self, linear_mps: float, angular_rps: float) -> None:
        if self._closed:
            return
        try:
            self._output.send(linear_mps, angular_rps)
            self.stats["published"] += 1
        except Exception:  # never let a publisher error kill the deadman
            self.stats["publish_errors"] += 1
            log.exception("could not publish the teleop command")

    def _publish_zero(self) -> None:
        if self._closed:
            return
        try:
            self._output.zero()
            self.stats["zeros"] += 1
        except Exception:
            self.stats["publish_errors"] += 1
            log.exception("could not publish the teleop stop")

    def _last_stop_reason(self) -> str:
        return self._last_stop["reason"] if self._last_stop else "stopped"

    def _state(self) -> dict:
        command, holder = self._command, self._holder
        return {
            "linear_mps": round(command.linear_mps, 4) if command else 0.0,
            "angular_rps": round(command.angular_rps, 4) if command else 0.0,
            "moving": bool(command and (command.linear_mps or command.angular_rps)),
            "ramping": self._ramping,
            "source": command.source if command else None,
            "holder": holder.public() if holder else None,
            "operators": len(self._sessions),
            "estop": dict(self._estop),
            "last_stop": dict(self._last_stop) if self._last_stop else None,
            "max_linear_mps": self.limits.max_linear_mps,
            "max_angular_rps": self.limits.max_angular_rps,
            "rate_hz": self.rate_hz,
            "deadman_s": self.deadman_s,
            "deadman_max_s": self.deadman_max_s,
        }

    def _changed(self) -> None:
        if self._on_state is None:
            return
        state = self._state()
        if state != self._shown:
            self._shown = state
            try:
                self._on_state(state)
            except Exception:
                log.exception("teleop state listener failed")
