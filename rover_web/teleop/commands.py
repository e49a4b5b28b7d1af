"""What a teleop command is: directions, limits, scaling, the command held, and a refusal. Pure Python."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rover_web.web.api_messages import as_text

if TYPE_CHECKING:
    from .sessions import Session

# POST /api/teleop commands as (linear, angular) directions; +angular turns left (REP 103).
REST_COMMANDS: dict[str, tuple[float, float]] = {
    "forward": (1.0, 0.0), "back": (-1.0, 0.0), "left": (0.0, 1.0), "right": (0.0, -1.0),
}
# Where a socket's drive frames come from: the page's own controls. The rules are the same for all;
# the source is kept in the state (SSE `teleop`) and logged when a socket starts using another.
SOURCES = ("joystick", "keyboard", "gamepad")


@dataclass(frozen=True)
class Limits:
    max_linear_mps: float
    max_angular_rps: float


def fraction(value: Any) -> float:
    """A joystick axis as a fraction in [-1, 1]; anything non-finite or not a number is 0 (stop)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return 0.0
    try:
        value = float(value)
    except OverflowError:  # an integer too large for a float: no more a number to drive by than inf
        return 0.0
    if not math.isfinite(value):
        return 0.0
    return max(-1.0, min(1.0, value))


def scale(linear: Any, angular: Any, limits: Limits) -> tuple[float, float]:
    """Joystick fractions to (m/s, rad/s): always finite and within the configured maxima."""
    return fraction(linear) * limits.max_linear_mps, fraction(angular) * limits.max_angular_rps


@dataclass
class Command:
    linear_mps: float
    angular_rps: float
    source: str                  # joystick | keyboard | gamepad | rest
    session: Session | None      # None for REST
    fresh_at: float              # when its input was fresh: a socket's frame dates from when it was sent
    expires_at: float            # the hard bound after fresh_at, or the end of a REST command's duration
    owner: object = None         # a REST command's starter (rest_drive.py), so only its revocation ends it


class Refused(Exception):
    """A request the controller will not carry out; `status` is the HTTP status it maps to."""

    def __init__(self, code: str, message: str, status: int = 409, **extra: Any):
        self.text = as_text(message, {})
        super().__init__(self.text.english())
        self.code, self.message, self.status, self.extra = code, self.text.english(), status, extra

    def as_frame(self, catalogues: tuple | None = None) -> dict:
        """The error frame, its message in the language of `catalogues` (the socket's)."""
        return {"type": "error", "error": self.code, "message": self.text.translated(catalogues),
                "status": self.status, **self.extra}
