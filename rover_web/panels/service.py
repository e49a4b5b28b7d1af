"""The panels' ROS side and command path: subscriptions feed the displays, commands go out checked.

Every command is decided here, whatever sent it (the page, curl, a script): unknown panel or
control 404, malformed value 400, locked or not allowed in the current state 409, and in every
refusal nothing is published. Accepted and refused commands alike land in the operator log.
Refusals are PanelError subclasses; routes.py turns them into HTTP answers.
"""

from __future__ import annotations

import logging
import sqlite3
import threading
import time
from typing import Any

from rover_web.core.rate_limit import RateLimit
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.web.api_messages import explain, text_of
from rover_web.web.validate import InvalidInput, only_keys

from . import msgs
from .oplog import OperatorLog
from .scalars import InvalidValue
from .spec import ControlSpec, PanelSpec
from .state import PanelState

log = logging.getLogger(__name__)

# Display updates reach browsers at most this often; a status is read by a person.
VIEW_MAX_HZ = 10.0
# How often lock timeouts and staleness are re-checked when no message arrives to trigger it.
TICK_S = 0.25


class PanelError(Exception):
    """A panel action that was not carried out; `code` is the short machine-readable reason."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


class UnknownPanel(PanelError):
    pass


class UnknownControl(PanelError):
    pass


class InvalidCommand(PanelError):
    """A command the client must fix: unreadable body, bad value, missing confirmation."""


class CommandRefused(PanelError):
    """A well-formed command the panel's state does not allow now (`locked`, `not_allowed`)."""


class TooMany(PanelError):
    """A client over its rate of unlock attempts or refused commands; nothing is done or logged."""

    def __init__(self, message: str, retry_after_s: float):
        super().__init__(message, "rate_limited")
        self.retry_after_s = retry_after_s


class PanelService:
    def __init__(self, specs: tuple[PanelSpec, ...], rover: Rover, oplog: OperatorLog, estop: EStopService):
        self.rover = rover
        self.oplog = oplog
        self.estop = estop
        self.specs = {s.id: s for s in specs}
        self.states = {s.id: PanelState(s, estop_engaged=lambda: estop.engaged) for s in specs}
        # Per client: every refusal and unlock writes the operator log that everyone reads.
        self.refusals = RateLimit(rover.config["ROVER_WEB_PANEL_REFUSALS_PER_MIN"], 60.0)
        self.unlocks = RateLimit(rover.config["ROVER_WEB_PANEL_UNLOCKS_PER_MIN"], 60.0)
        self._view_lock = threading.Lock()
        self._last_view: dict | None = None
        runtime = rover.runtime
        self._publishers: dict[str, Any] = {}
        for spec in specs:
            for control in spec.controls:
                if control.topic not in self._publishers:
                    # Volatile, depth 1: a late subscriber must never receive an old "take off".
                    self._publishers[control.topic] = runtime.publisher(control.type.name, control.topic, "command")
        by_topic: dict[str, list] = {}
        for spec in specs:
            for display in spec.displays:
                by_topic.setdefault(display.topic, []).append((self.states[spec.id], display))
        for topic, readers in by_topic.items():
            display = readers[0][1]
            runtime.subscribe(display.type, topic, self._reader(readers), display.qos)

    # --- displays ---

    def _reader(self, readers):
        def on_message(msg) -> None:
            now = time.monotonic()
            for state, display in readers:
                state.update(display.id, msgs.read_field(msg, display.field), now)
            self.publish_view()
        return on_message

    def detail(self, panel_id: str) -> dict:
        """The API's view of one panel, with how many subscribers each control's topic has."""
        detail = self.panel(panel_id).detail()
        for control in detail["controls"]:
            control["subscribers"] = self._publishers[control["topic"]].get_subscription_count()
        return detail

    def views(self) -> dict[str, dict]:
        now = time.monotonic()
        return {pid: state.view(now) for pid, state in self.states.items()}

    def publish_view(self) -> None:
        """Send the `panel` channel if anything an operator sees changed (values, staleness, lock, rules)."""
        with self._view_lock:  # computed under the lock, so an older view can never be sent after a newer one
            views = self.views()
            if views == self._last_view:
                return
            self._last_view = views
            self.rover.hub.publish_throttled("panel", {"panels": views}, VIEW_MAX_HZ)

    # --- ticker: lock timeouts and staleness, which no message announces ---

    def tick(self) -> None:
        """Run every TICK_S: re-lock timed-out panels and send the view if staleness changed it."""
        for state in self.states.values():
            with state.lock:
                self._expire(state)
        self.publish_view()

    def _expire(self, state: PanelState) -> None:
        """Lock a panel whose unlock timed out, and say so in its log (call with state.lock held)."""
        if state.expire():
            self._record(state.spec.id, "lock", "Lock", None, "locked",
                         f"no command for {state.spec.unlock_timeout_s:g} s", "")

    # --- operator actions ---

    def panel(self, panel_id: str) -> PanelState:
        state = self.states.get(panel_id)
        if state is None:
            raise UnknownPanel(explain("no panel %(panel_id)s; panels: %(specs)s",
                                       panel_id=repr(panel_id[:40]), specs=', '.join(self.specs)), "unknown_panel")
        return state

    def unlock(self, panel_id: str, client: str) -> dict:
        state = self.panel(panel_id)
        wait = self.unlocks.hit(client)
        if wait:
            raise TooMany(explain("too many unlock attempts (ROVER_WEB_PANEL_UNLOCKS_PER_MIN); try again in "
                                  "%(value)s s",
                                  value=max(1, int(wait + 0.999))), wait)
        with state.lock:
            self._expire(state)
            state.unlock()
            entry = self._record(panel_id, "unlock", "Unlock", None, "unlocked",
                                 f"re-locks after {state.spec.unlock_timeout_s:g} s without a command", client)
        self.publish_view()
        return {"panel": panel_id, "locked": False, "unlock_timeout_s": state.spec.unlock_timeout_s,
                "log": entry, "state": state.view()}

    def lock(self, panel_id: str, client: str) -> dict:
        state = self.panel(panel_id)
        entry = None
        with state.lock:
            self._expire(state)
            if state.relock():
                entry = self._record(panel_id, "lock", "Lock", None, "locked", "by the operator", client)
        self.publish_view()
        return {"panel": panel_id, "locked": True, "log": entry, "state": state.view()}

    def command(self, panel_id: str, control_id: str, body_or_error: dict | InvalidCommand, client: str) -> dict:
        """Check and publish one command; a PanelError (logged) for anything that is not sent.

        `body_or_error` is the request body, or why it could not be read: that is still logged as
        an invalid command, but only once the panel and control are known to exist.
        """
        state = self.panel(panel_id)
        control = state.spec.control(control_id)
        if control is None:
            raise UnknownControl(
                explain(
                    "panel %(panel_id)s has no control %(control_id)s; controls: %(value)s",
                    panel_id=repr(panel_id),
                    control_id=repr(control_id[:40]),
                    value=", ".join(c.id for c in state.spec.controls),
                ),
                "unknown_control",
            )
        wait = self.refusals.retry_after_s(client)
        if wait:  # checked before anything is logged: a client hammering refusals writes nothing more
            raise TooMany(explain("too many refused commands (ROVER_WEB_PANEL_REFUSALS_PER_MIN); try again in "
                                  "%(value)s s",
                                  value=max(1, int(wait + 0.999))), wait)
        if isinstance(body_or_error, InvalidCommand):
            self._refuse(state, control, None, "invalid", body_or_error, client)
        body = body_or_error
        try:
            only_keys(body, {"confirmed"} if control.kind == "button" else {"value", "confirmed"})
            value = state.value_for(control, body)
            confirmed = body.get("confirmed", False)
            if not isinstance(confirmed, bool):
                raise InvalidInput("'confirmed' must be true or false, got %(type)s", "bad_type",
                                   type=type(confirmed).__name__)
        except (InvalidInput, InvalidValue) as exc:
            self._refuse(state, control, body.get("value"), "invalid", InvalidCommand(text_of(exc), exc.code), client)
        if control.confirm and not confirmed:
            self._refuse(state, control, value, "invalid", InvalidCommand(
                explain("%(label)s needs a confirmation: send {\"confirmed\": true} with the request",
                        label=control.label),
                "confirmation_required"), client)
        with state.lock:
            self._expire(state)
            refusal = state.refusal(control)
            if refusal is not None:
                self._refuse(
                    state, control, value, "refused", CommandRefused(refusal.reason_text, refusal.code), client
                )
            self._publishers[control.topic].publish(msgs.scalar_message(control.type.name, value))
            state.renew()
            entry = self._record(panel_id, control.id, control.label, value, "sent", "", client)
        self.publish_view()
        return {"result": "sent", "panel": panel_id, "control": control.id, "topic": control.topic,
                "type": control.type.name, "value": value, "log": entry}

    def on_estop(self, by: str) -> None:
        """The e-stop engaged: send each panel's `on_estop` button, whatever its lock and rules say."""
        for state in self.states.values():
            control = state.spec.control(state.spec.on_estop) if state.spec.on_estop else None
            if control is None:
                continue
            with state.lock:
                self._publishers[control.topic].publish(msgs.scalar_message(control.type.name, control.value))
                self._record(state.spec.id, control.id, control.label, control.value, "sent",
                             f"e-stop engaged by {by}", "e-stop")
        self.publish_view()

    def _refuse(self, state: PanelState, control: ControlSpec, value: Any, result: str, error: PanelError,
                client: str) -> None:
        self.refusals.record(client)
        self._record(state.spec.id, control.id, control.label, value, result, str(error), client)
        raise error

    def _record(self, panel_id: str, control: str, label: str, value: Any, result: str, reason: str,
                client: str) -> dict | None:
        """Log to SQLite and to the `panel_log` channel; a failing disk never blocks a command."""
        try:
            entry = self.oplog.record(panel_id, control, label, value, result, reason, client)
        except sqlite3.Error:
            log.exception("could not write the operator log")
            return None
        self.rover.hub.emit("panel_log", entry)
        return entry
