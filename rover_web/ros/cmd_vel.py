"""The one place velocity commands leave the process.

Every feature that moves the robot goes through CmdVelOutput, so the last line of defence (finite
values, clamped to the configured maxima, nothing after shutdown) is enforced once.
"""

from __future__ import annotations

import math
import threading

from .convert import twist_message


def clamp(value: float, limit: float) -> float:
    """Clamp to [-limit, limit]; anything non-finite becomes 0 (stop), never a command."""
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        return 0.0
    return max(-limit, min(limit, float(value)))


class CmdVelOutput:
    def __init__(self, runtime, topic: str, *, max_linear_mps: float, max_angular_rps: float,
                 stamped: bool = False, frame_id: str = "base_link"):
        self._runtime = runtime
        self._stamped = stamped
        self.max_linear_mps = max_linear_mps
        self.max_angular_rps = max_angular_rps
        msg_type = "geometry_msgs/msg/TwistStamped" if stamped else "geometry_msgs/msg/Twist"
        self._publisher = runtime.publisher(msg_type, topic, qos=10)
        # One message, refilled under the lock for every publish: publish() copies it out before it
        # returns, and a fresh Twist is three Python objects to build on the path from a joystick
        # frame to the wire (bench/teleop.py).
        self._msg = twist_message(0.0, 0.0, stamped=stamped, frame_id=frame_id)
        self._twist = self._msg.twist if stamped else self._msg
        # Re-entrant: the process's stop-signal handler (rover_web/process.py) calls halt() on the
        # main thread, which may be inside halt() already (a second Ctrl-C while stopping).
        self._lock = threading.RLock()
        self._halted = False
        self._held = False  # the e-stop's hold: only zero goes out until release_hold()
        self.last = (0.0, 0.0)

    @property
    def halted(self) -> bool:
        return self._halted

    def send(self, linear_mps: float, angular_rps: float) -> tuple[float, float]:
        """Publish one command (clamped); returns what was published. Only zero once halted or held."""
        linear = clamp(linear_mps, self.max_linear_mps)
        angular = clamp(angular_rps, self.max_angular_rps)
        with self._lock:
            if self._halted or self._held:
                linear = angular = 0.0
            self._publish(linear, angular)
        return linear, angular

    def zero(self) -> None:
        with self._lock:
            self._publish(0.0, 0.0)

    def hold_zero(self) -> None:
        """The e-stop: zero now, and nothing but zero until release_hold().

        The e-stop's zero goes out before its hooks tell teleop, and in between teleop's repeater
        (or a joystick frame already past its checks) could still send the held command: a
        motion after the stop. Held here, at the one place velocity leaves the process, it is
        sent as zero instead (caught by tests/browser/test_gamepad.py under load).
        """
        with self._lock:
            self._held = True
            self._publish(0.0, 0.0)

    def release_hold(self) -> None:
        with self._lock:
            self._held = False

    def halt(self) -> None:
        """Shutdown: a zero command goes out now, and nothing but zero after it."""
        with self._lock:
            self._halted = True
            self._publish(0.0, 0.0)

    def _publish(self, linear: float, angular: float) -> None:
        if self._stamped:
            self._msg.header.stamp = self._runtime.now_msg()
        self._twist.linear.x = linear
        self._twist.angular.z = angular
        self._publisher.publish(self._msg)
        self.last = (linear, angular)
