"""What a held joystick command is worth as its last fresh input ages: hold, ramp down, stop. Pure.

    age < hold_s             1           the last command, as sent: a short gap (a stall, jitter) goes unnoticed
    hold_s <= age < bound_s  falling     linearly from 1 to 0: the robot eases off instead of lurching to a halt
    age >= bound_s           0, expired  the controller publishes zero, ends the command and bumps the epoch

`hold_s` is ROVER_WEB_TELEOP_DEADMAN_S and `bound_s` ROVER_WEB_TELEOP_DEADMAN_MAX_S. The factor
scales both axes alike, so the robot keeps its arc while it slows. For any age, NaN included, it
is a finite number in [0, 1] that never grows as the age grows: the published speed is never above
the last command, only ever moves toward zero until a fresh input comes, and reaches zero at
the bound whatever happens. With bound_s == hold_s there is no ramp: hold, then stop (the rule
before the ramp existed).
"""

from __future__ import annotations

import math


class Ramp:
    def __init__(self, hold_s: float, bound_s: float):
        if not (math.isfinite(hold_s) and math.isfinite(bound_s) and 0 < hold_s <= bound_s):
            raise ValueError(f"need 0 < hold_s <= bound_s, finite; got {hold_s!r}, {bound_s!r}")
        self.hold_s = hold_s
        self.bound_s = bound_s

    def factor(self, age_s: float) -> float:
        """The share of the last command to publish `age_s` after its input was fresh."""
        if not age_s < self.bound_s:  # also NaN: an age nobody can vouch for is past the bound
            return 0.0
        if age_s <= self.hold_s:
            return 1.0
        return (self.bound_s - age_s) / (self.bound_s - self.hold_s)  # bound_s > age_s > hold_s here

    def expired(self, age_s: float) -> bool:
        return not age_s < self.bound_s

    def scaled(self, linear: float, angular: float, age_s: float) -> tuple[float, float]:
        f = self.factor(age_s)
        return linear * f, angular * f
