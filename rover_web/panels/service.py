"""The panels' ROS side and command path: subscriptions feed the displays, commands go out checked.

Every command is decided here, whatever sent it (the page, curl, a script): unknown panel or
control 404, malformed value 400, locked or not allowed in the current state 409, and in every
refusal nothing is published. Accepted and refused commands alike land in the operator log.
"""

from __future__ import annotations

import logging
import sqlite3
import threading
import time
from typing import Any

from rover_web.web.http import ApiError
from . import msgs as panel_msgs
from rover_web.web.validate import InvalidInput, only_keys
from .oplog import OperatorLog
from .spec import ControlSpec, InvalidValue, PanelSpec
from .state import PanelState

log = logging.getLogger(__name__)

# Display updates reach browsers at most this often; a status is read by a person.
VIEW_MAX_HZ = 10.0
# How often lock timeouts and staleness are re-checked when no message arrives to trigger it.
TICK_S = 0.25


class PanelService:
    def __init__(self, specs: tuple[PanelSpec, ...], rover, oplog: OperatorLog):
        self.rover = rover
        self.oplog = oplog
        self.specs = {s.id: s for s in specs}
        self.states = {s.id: PanelState(s) for s in specs}
        self._view_lock = threading.Lock()
        self._last_view: dict | None = None
        self._thread: threading.Thread | None = None
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
                state.update(display.id, panel_msgs.read_field(msg, display.field), now)
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

    def start(self) -> None:
        self.publish_view()
        self._thread = threading.Thread(target=self._tick_loop, name="panels-ticker", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        if self._thread is not None:
            self._thread.join(2 * TICK_S + 1.0)

    def _tick_loop(self) -> None:
        while not self.rover.stopping.wait(TICK_S):
            try:
                for state in self.states.values():
                    with state.lock:
                        self._expire(state)
                self.publish_view()
            except Exception:  # pragma: no cover - the ticker must not die silently
                log.exception("panels ticker failed")

    def _expire(self, state: PanelState) -> None:
        """Lock a panel whose unlock timed out, and say so in its log (call with state.lock held)."""
        if state.expire():
            self._record(state.spec.id, "lock", "Lock", None, "locked",
                         f"no command for {state.spec.unlock_timeout_s:g} s", "")

    # --- operator actions ---

    def panel(self, panel_id: str) -> PanelState:
        state = self.states.get(panel_id)
        if state is None:
            raise ApiError(404, "unknown_panel",
                           f"no panel {panel_id[:40]!r}; panels: {', '.join(self.specs)}")
        return state

    def unlock(self, panel_id: str, client: str) -> dict:
        state = self.panel(panel_id)
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

    def command(self, panel_id: str, control_id: str, body_or_error: dict | ApiError, client: str) -> dict:
        """Check and publish one command; ApiError (logged) for anything that is not sent."""
        state = self.panel(panel_id)
        control = state.spec.control(control_id)
        if control is None:
            raise ApiError(404, "unknown_control",
                           f"panel {panel_id!r} has no control {control_id[:40]!r}; controls: "
                           f"{', '.join(c.id for c in state.spec.controls)}")
        if isinstance(body_or_error, ApiError):
            self._refuse(state, control, None, "invalid", body_or_error, client)
        body = body_or_error
        try:
            only_keys(body, {"confirmed"} if control.kind == "button" else {"value", "confirmed"})
            value = state.value_for(control, body)
            confirmed = body.get("confirmed", False)
            if not isinstance(confirmed, bool):
                raise InvalidInput(f"'confirmed' must be true or false, got {type(confirmed).__name__}", "bad_type")
        except (InvalidInput, InvalidValue) as exc:
            self._refuse(state, control, body.get("value"), "invalid", ApiError(400, exc.code, str(exc)), client)
        if control.confirm and not confirmed:
            self._refuse(state, control, value, "invalid", ApiError(
                400, "confirmation_required",
                f"{control.label} needs a confirmation: send {{\"confirmed\": true}} with the request"), client)
        with state.lock:
            self._expire(state)
            refusal = state.refusal(control)
            if refusal is not None:
                self._refuse(state, control, value, "refused", ApiError(409, refusal.code, refusal.reason), client)
            self._publishers[control.topic].publish(panel_msgs.scalar_message(control.type.name, value))
            state.renew()
            entry = self._record(panel_id, control.id, control.label, value, "sent", "", client)
        self.publish_view()
        return {"result": "sent", "panel": panel_id, "control": control.id, "topic": control.topic,
                "type": control.type.name, "value": value, "log": entry}

    def _refuse(self, state: PanelState, control: ControlSpec, value: Any, result: str, error: ApiError,
                client: str) -> None:
        self._record(state.spec.id, control.id, control.label, value, result, error.message, client)
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
