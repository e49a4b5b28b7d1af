"""A simulated drone that obeys the mission control panel's topics.

Subscribes /control_phase (std_msgs/Int8: 1 take off, 2 return, 0 stop), /flight_destination
(Int8: fly to that AprilTag) and /flight_height (Int8: altitude in metres for the next climb);
publishes /status (String: Standby, Flying, Hovering), /id (Int8: the tag below, -1 between tags),
/location (geometry_msgs/Point: metres from the home pad) and /flight_height (its altitude
setting) at a steady rate, and at once on every change. The names are relative: /status at the
root, /drone/status in a robot's namespace (`--robots drone`).

    Standby --take off--> Flying --> Hovering (above the pad, tag 0)
    Hovering --destination k--> Flying --> Hovering above tag k
    Hovering --return--> Flying --> Standby (landed on the pad)
    Flying --stop--> Hovering where it is (a multirotor holds position; landing blind could put
                     it in water or on people, so stop never lands)

Commands that do not fit the current status are ignored and logged, as a flight controller
would. Tag k sits at ((k mod 5) * spacing, (k div 5) * spacing); tag 0 is the home pad. Every
manoeuvre takes --drone-transition-s, so tests can make the drone fast.
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass

from geometry_msgs.msg import Point
from rclpy.node import Node
from std_msgs.msg import Int8, String

from rover_web.ros import qos

STANDBY, FLYING, HOVERING = "Standby", "Flying", "Hovering"
PHASE_STOP, PHASE_TAKE_OFF, PHASE_RETURN = 0, 1, 2
TAGS_PER_ROW = 5
NO_TAG = -1


@dataclass(frozen=True)
class Leg:
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    t0: float
    duration_s: float
    then_status: str
    then_tag: int


class DroneModel:
    """Pure flight logic (no ROS), so it can be unit-tested with a fake clock."""

    def __init__(self, transition_s: float = 3.0, height_m: int = 5, tag_spacing_m: float = 4.0):
        self.transition_s = transition_s
        self.height_m = height_m
        self.tag_spacing_m = tag_spacing_m
        self.status = STANDBY
        self.tag = 0
        self._position = (0.0, 0.0, 0.0)
        self._leg: Leg | None = None

    def tag_position(self, tag: int) -> tuple[float, float]:
        return ((tag % TAGS_PER_ROW) * self.tag_spacing_m, (tag // TAGS_PER_ROW) * self.tag_spacing_m)

    def tag_at(self, x: float, y: float) -> int:
        col, row = round(x / self.tag_spacing_m), round(y / self.tag_spacing_m)
        tag = row * TAGS_PER_ROW + col
        if 0 <= col < TAGS_PER_ROW and 0 <= tag <= 127 and math.dist((x, y), self.tag_position(tag)) < 0.25:
            return tag
        return NO_TAG

    def position(self, now: float) -> tuple[float, float, float]:
        leg = self._leg
        if leg is None:
            return self._position
        f = min(1.0, max(0.0, (now - leg.t0) / leg.duration_s))
        return tuple(a + (b - a) * f for a, b in zip(leg.start, leg.end, strict=True))  # type: ignore[return-value]

    def step(self, now: float) -> bool:
        """Finish the current manoeuvre if its time is up; True if the status changed."""
        leg = self._leg
        if leg is None or now < leg.t0 + leg.duration_s:
            return False
        self._position, self._leg = leg.end, None
        changed = self.status != leg.then_status or self.tag != leg.then_tag
        self.status, self.tag = leg.then_status, leg.then_tag
        return changed

    def _fly(self, end: tuple[float, float, float], now: float, then_status: str, then_tag: int) -> None:
        self._leg = Leg(self.position(now), end, now, self.transition_s, then_status, then_tag)
        self._position = self._leg.start
        self.status, self.tag = FLYING, NO_TAG

    def control_phase(self, phase: int, now: float) -> str:
        """Apply /control_phase; returns what the drone did, for its log."""
        self.step(now)
        x, y, z = self.position(now)
        if phase == PHASE_TAKE_OFF:
            if self.status != STANDBY:
                return f"take off ignored: the drone is {self.status}, not {STANDBY}"
            self._fly((x, y, float(self.height_m)), now, HOVERING, self.tag_at(x, y))
            return f"taking off to {self.height_m} m"
        if phase == PHASE_RETURN:
            if self.status != HOVERING:
                return f"return ignored: the drone is {self.status}, not {HOVERING}"
            self._fly((0.0, 0.0, 0.0), now, STANDBY, 0)
            return "returning to the home pad"
        if phase == PHASE_STOP:
            if self.status != FLYING:
                return f"stop: already {self.status}"
            self._position, self._leg = (x, y, z), None
            if z < 0.05:  # stopped before leaving the ground
                self.status, self.tag = STANDBY, self.tag_at(x, y)
                return "stop: still on the ground"
            self.status, self.tag = HOVERING, self.tag_at(x, y)
            return f"stop: hovering at {x:.1f}, {y:.1f}, {z:.1f} m"
        return f"control phase {phase} ignored: expected 0 (stop), 1 (take off) or 2 (return)"

    def fly_to(self, tag: int, now: float) -> str:
        self.step(now)
        if self.status != HOVERING:
            return f"destination {tag} ignored: the drone is {self.status}, not {HOVERING}"
        if not 0 <= tag <= 127:
            return f"destination {tag} ignored: AprilTag ids are 0 to 127"
        z = self.position(now)[2]
        self._fly((*self.tag_position(tag), z), now, HOVERING, tag)
        return f"flying to tag {tag}"

    def set_height(self, height_m: int, now: float) -> str:
        self.step(now)
        if height_m < 1:
            return f"flight height {height_m} ignored: it must be at least 1 m"
        self.height_m = height_m
        if self.status == HOVERING:
            x, y, _z = self.position(now)
            self._fly((x, y, float(height_m)), now, HOVERING, self.tag)
            return f"climbing or descending to {height_m} m"
        return f"flight height set to {height_m} m"


class OwnEcho:
    """Recognises our own /flight_height reports when they come back to our own subscription.

    The drone both publishes and subscribes /flight_height, and rclpy cannot ignore local
    publications, so a report could be taken for a command. DDS stamps each sample with the
    writer's clock at write time: a sample whose source timestamp falls inside one of our own
    publish() calls is our echo.
    """

    def __init__(self, keep: int = 64):
        self._windows: deque[tuple[int, int]] = deque(maxlen=keep)

    def published(self, start_ns: int, end_ns: int) -> None:
        self._windows.append((start_ns, end_ns))

    def is_own(self, source_timestamp_ns: int) -> bool:
        return any(start <= source_timestamp_ns <= end for start, end in self._windows)


class DroneSim(Node):
    def __init__(self, *, context=None, transition_s: float = 3.0, rate_hz: float = 5.0, height_m: int = 5,
                 namespace: str = "/"):
        super().__init__("sim_drone", namespace=namespace, context=context)
        self.model = DroneModel(transition_s=transition_s, height_m=height_m)
        self._echo = OwnEcho()
        self._lock = threading.Lock()  # the executor is multi-threaded; one command at a time
        command_qos = qos.profile("default")
        self.create_subscription(Int8, "control_phase", self._on_control_phase, command_qos)
        self.create_subscription(Int8, "flight_destination", self._on_destination, command_qos)
        self.create_subscription(Int8, "flight_height", self._on_height, command_qos)
        self.status_pub = self.create_publisher(String, "status", 10)
        self.id_pub = self.create_publisher(Int8, "id", 10)
        self.location_pub = self.create_publisher(Point, "location", 10)
        self.height_pub = self.create_publisher(Int8, "flight_height", 10)
        self.create_timer(1.0 / rate_hz, self._tick)

    def _command(self, apply, value: int) -> None:
        with self._lock:
            self.get_logger().info(apply(value, time.monotonic()))
            self._report()  # a status change is shown at once, not at the next tick

    def _on_control_phase(self, msg: Int8) -> None:
        self._command(self.model.control_phase, msg.data)

    def _on_destination(self, msg: Int8) -> None:
        self._command(self.model.fly_to, msg.data)

    def _on_height(self, msg: Int8, info: dict) -> None:
        if self._echo.is_own(info.get("source_timestamp", -1)):
            return
        self._command(self.model.set_height, msg.data)

    def _tick(self) -> None:
        with self._lock:
            self._report()

    def _report(self) -> None:
        model, now = self.model, time.monotonic()
        model.step(now)
        self.status_pub.publish(String(data=model.status))
        self.id_pub.publish(Int8(data=model.tag))
        x, y, z = model.position(now)
        self.location_pub.publish(Point(x=x, y=y, z=z))
        start = time.time_ns()
        self.height_pub.publish(Int8(data=model.height_m))
        self._echo.published(start, time.time_ns())


def add_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("drone")
    group.add_argument("--drone-transition-s", type=float, default=3.0, metavar="S",
                       help="seconds each manoeuvre (take off, flight to a tag, return) takes (default 3)")
    group.add_argument("--drone-rate-hz", type=float, default=5.0, metavar="HZ",
                       help="rate of /status, /id, /location and /flight_height (default 5)")
    group.add_argument("--drone-height", type=int, default=5, metavar="M",
                       help="flight height in metres until /flight_height sets another (default 5)")


def from_arguments(args: argparse.Namespace, context, namespace: str = "/", east_offset_m: float = 0.0) -> DroneSim:
    if not args.drone_transition_s > 0 or not args.drone_rate_hz > 0 or not 1 <= args.drone_height <= 127:
        raise SystemExit("drone: --drone-transition-s and --drone-rate-hz must be positive, "
                         "--drone-height from 1 to 127")
    return DroneSim(context=context, transition_s=args.drone_transition_s, rate_hz=args.drone_rate_hz,
                    height_m=args.drone_height, namespace=namespace)


def main(argv: list[str] | None = None) -> None:
    from .runner import run_part
    run_part(sys.modules[__name__], argv)


if __name__ == "__main__":
    main()
