"""One control panel's live state: what its displays show, whether it is unlocked, what is allowed.

The rules the page shows (which buttons are enabled, and why not) and the rules the server
enforces come from the same `refusal()` call, so they cannot disagree. Pure Python with an
injectable clock; thread-safe (ROS callbacks, request threads and the ticker all touch it).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from rover_web.web.api_messages import Text, explain, said, text_of, with_wire

from .scalars import InvalidValue, coerce
from .spec import ControlSpec, DisplaySpec, PanelSpec


@dataclass(frozen=True)
class Refusal:
    """Why a control cannot be used now: `code` is `locked` or `not_allowed`."""

    code: str
    reason: Text

    @property
    def reason_text(self) -> Text:
        return self.reason


def _either(values) -> Text | str:
    """"Standby or Hovering", in each viewer's language (a said sentence nests: "A or B or C")."""
    text: Text | str = str(values[0])
    for value in values[1:]:
        text = said("%(some)s or %(other)s", some=text, other=str(value))
    return text


def format_value(display: DisplaySpec, value: Any) -> str:
    """The text an operator reads: floats to the display's digits, messages as `k v · k v`."""
    if value is None:
        return "—"
    unit = f" {display.unit}" if display.unit else ""
    return _format(value, display.digits) + unit


def _format(value: Any, digits: int) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    if isinstance(value, dict):
        return " · ".join(f"{k} {_format(v, digits)}" for k, v in value.items())
    if isinstance(value, list):
        return "[" + ", ".join(_format(v, digits) for v in value) + "]"
    return str(value)


class PanelState:
    def __init__(self, spec: PanelSpec, clock: Callable[[], float] = time.monotonic,
                 estop_engaged: Callable[[], bool] = lambda: False):
        self.spec = spec
        self._clock = clock
        self._estop_engaged = estop_engaged
        self._lock = threading.RLock()
        self._values: dict[str, Any] = {}
        self._received_at: dict[str, float] = {}
        self._unlocked_until: float | None = None

    @property
    def lock(self) -> threading.RLock:
        """Held by the command path so that check, publish and renewal happen as one step."""
        return self._lock

    # --- displays ---

    def update(self, display_id: str, value: Any, now: float | None = None) -> None:
        now = self._clock() if now is None else now
        with self._lock:
            self._values[display_id] = value
            self._received_at[display_id] = now

    def reading(self, display_id: str, now: float) -> tuple[Any, float | None, bool]:
        """(value, age in seconds or None, fresh)."""
        with self._lock:
            if display_id not in self._received_at:
                return None, None, False
            age = max(0.0, now - self._received_at[display_id])
            return self._values[display_id], age, age <= self.spec.stale_after_s

    # --- unlock ---

    def locked(self, now: float | None = None) -> bool:
        now = self._clock() if now is None else now
        with self._lock:
            return self._unlocked_until is None or now >= self._unlocked_until

    def unlock(self, now: float | None = None) -> None:
        now = self._clock() if now is None else now
        with self._lock:
            self._unlocked_until = now + self.spec.unlock_timeout_s

    def relock(self) -> bool:
        """Lock now; True if it was unlocked."""
        with self._lock:
            was_unlocked = not self.locked()
            self._unlocked_until = None
            return was_unlocked

    def expire(self, now: float | None = None) -> bool:
        """Lock if the unlock timed out; True exactly once, when that happens."""
        now = self._clock() if now is None else now
        with self._lock:
            if self._unlocked_until is not None and now >= self._unlocked_until:
                self._unlocked_until = None
                return True
            return False

    def renew(self, now: float | None = None) -> None:
        """An accepted command is activity: the inactivity timeout starts again."""
        now = self._clock() if now is None else now
        with self._lock:
            if self._unlocked_until is not None and now < self._unlocked_until:
                self._unlocked_until = now + self.spec.unlock_timeout_s

    # --- rules ---

    def refusal(self, control: ControlSpec, now: float | None = None) -> Refusal | None:
        """None if `control` may be used now, else the reason (the e-stop, the lock, then the displays)."""
        now = self._clock() if now is None else now
        with self._lock:
            if self._estop_engaged() and not control.allowed_during_estop:
                return Refusal("estop_engaged", said("the e-stop is engaged: %(label)s is not sent until it is "
                                                     "released", label=control.label))
            if control.requires_unlock and self.locked(now):
                return Refusal("locked", said("the %(title)s panel is locked; unlock it first",
                                              title=self.spec.title))
            for display_id, allowed in control.enabled_when:
                display = self.spec.display(display_id)
                value, age, fresh = self.reading(display_id, now)
                wanted = _either(allowed)
                if age is None:
                    return Refusal("not_allowed", said("%(label)s needs %(display)s to be %(wanted)s; no "
                                                       "%(display)s has been received yet",
                                                       label=control.label, display=display.label, wanted=wanted))
                if not fresh:
                    return Refusal(
                        "not_allowed",
                        said(
                            "%(label)s needs %(display)s to be %(wanted)s; the last "
                            "%(display)s (%(value)s) is %(age)s s old",
                            label=control.label,
                            display=display.label,
                            wanted=wanted,
                            value=_format(value, display.digits),
                            age=format(age, ".1f"),
                        ),
                    )
                if not _matches(value, allowed):
                    return Refusal(
                        "not_allowed",
                        said(
                            "%(label)s is only allowed when %(display)s is %(wanted)s; it is %(value)s",
                            label=control.label,
                            display=display.label,
                            wanted=wanted,
                            value=_format(value, display.digits),
                        ),
                    )
        return None

    def value_for(self, control: ControlSpec, body: dict) -> Any:
        """The value a command publishes: a button's own, or an input's checked `value` field."""
        if control.kind == "button":
            return control.value
        if "value" not in body or body["value"] is None:
            raise InvalidValue(
                explain("'value' is required: the %(label)s to send", label=control.label), "missing_field"
            )
        try:
            return coerce(control.type, body["value"], low=control.low, high=control.high,
                          max_length=control.max_length)
        except InvalidValue as exc:
            raise InvalidValue(explain("'value' %(why)s", why=text_of(exc)), exc.code) from None

    # --- views ---

    def light(self, now: float) -> str:
        """green: no mission running; red: one is; unknown: nothing fresh to judge by."""
        light = self.spec.light
        if light is None:
            return "none"
        value, _age, fresh = self.reading(light.display, now)
        if not fresh:
            return "unknown"
        return "green" if _matches(value, light.idle) else "red"

    def view(self, now: float | None = None) -> dict:
        """What the page needs (the `panel` channel): no ages, so it only changes when something does."""
        now = self._clock() if now is None else now
        with self._lock:
            displays = {}
            for d in self.spec.displays:
                value, _age, fresh = self.reading(d.id, now)
                displays[d.id] = {"value": value, "text": format_value(d, value), "fresh": fresh}
            controls = {}
            for c in self.spec.controls:
                refusal = self.refusal(c, now)
                controls[c.id] = with_wire({"enabled": refusal is None, "reason": refusal.reason if refusal else ""})
            return {"locked": self.locked(now), "light": self.light(now), "displays": displays, "controls": controls}

    def detail(self, now: float | None = None) -> dict:
        """The API's view: the configuration with the current state and each display's age."""
        now = self._clock() if now is None else now
        spec = self.spec
        with self._lock:
            view = self.view(now)
            displays = []
            for d in spec.displays:
                _value, age, _fresh = self.reading(d.id, now)
                displays.append({"id": d.id, "label": d.label, "topic": d.topic, "type": d.type, "field": d.field,
                                 **view["displays"][d.id], "age_s": None if age is None else round(age, 3)})
            controls = [{**control_description(c), **view["controls"][c.id]} for c in spec.controls]
            return {"id": spec.id, "title": spec.title, "locked": view["locked"],
                    "unlock_timeout_s": spec.unlock_timeout_s, "stale_after_s": spec.stale_after_s,
                    "light": None if spec.light is None else {
                        "display": spec.light.display, "idle": list(spec.light.idle),
                        "label": spec.light.label, "state": view["light"]},
                    "displays": displays, "controls": controls}


def control_description(c: ControlSpec) -> dict:
    out: dict[str, Any] = {"id": c.id, "kind": c.kind, "label": c.label, "topic": c.topic, "type": c.type.name}
    if c.kind == "button":
        out["value"] = c.value
    else:
        out["action"] = c.action
        if c.type.kind in ("int", "float"):
            out["min"], out["max"] = c.low, c.high
        if c.type.kind == "string":
            out["max_length"] = c.max_length
    out["enabled_when"] = {did: list(values) for did, values in c.enabled_when}
    out["confirm"] = c.confirm
    out["requires_unlock"] = c.requires_unlock
    out["allowed_during_estop"] = c.allowed_during_estop
    return out


def _matches(value: Any, allowed: tuple[Any, ...]) -> bool:
    # 1 == True in Python; a Bool display must not match an Int rule by accident, nor the reverse.
    return any(value == a and isinstance(value, bool) == isinstance(a, bool) for a in allowed)
