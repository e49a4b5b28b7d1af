"""The RobotX Scan the Code light buoy: a repeating three-colour code on /light_sequence.

Like the task's buoy it shows a random code of three colours from its set, no colour twice in a
row, each for `period` seconds, then black, and repeats; a new code comes on request (any
std_msgs/Empty on /light_buoy/new_code: the buoy goes black at once and shows the new code next)
or every N cycles. It stands in for the camera detector as well: the colour it shows is published
as std_msgs/String `rate` times a second while it is on, with optional message drops and
misreadings (noise), so the GUI's detector meets what a real one does.

The code it chose is the truth the tests compare with: published on /light_buoy/answer
(transient local, "red,green,blue") and printed as `light buoy code: red,green,blue`.
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from collections.abc import Sequence

from rclpy.node import Node
from std_msgs.msg import Empty, String

from rover_web.ros import qos
from rover_web.scan_the_code.light_sequence import BLACK, CODE_LENGTH, parse_colours

DEFAULT_COLOURS = ("red", "green", "blue", "yellow")
# What a confused detector might report instead of the true colour, besides other colours and black.
MISREADINGS = ("purple", "", "RED?", "<b>red</b>", "unknown")


def random_code(rng: random.Random, colours: Sequence[str], avoid: Sequence[str] | None = None) -> tuple[str, ...]:
    """Three colours from `colours`, never the same twice in a row; different from `avoid` if given."""
    while True:
        code: list[str] = []
        for _ in range(CODE_LENGTH):
            code.append(rng.choice([c for c in colours if not code or c != code[-1]]))
        if avoid is None or tuple(code) != tuple(avoid):
            return tuple(code)


class BuoyClock:
    """Which light shows when: pure, so the timing can be unit-tested without ROS."""

    def __init__(self, code: Sequence[str], period_s: float, black_s: float, start: float):
        self.code = tuple(code)
        self.period_s, self.black_s = period_s, black_s
        self.cycle_start = start
        self.cycles = 0  # completed cycles

    @property
    def cycle_s(self) -> float:
        return CODE_LENGTH * self.period_s + self.black_s

    def advance(self, now: float) -> int:
        """Move past finished cycles; returns how many just finished."""
        finished = 0
        while now - self.cycle_start >= self.cycle_s:
            self.cycle_start += self.cycle_s
            finished += 1
        self.cycles += finished
        return finished

    def light(self, now: float) -> str:
        index = int((now - self.cycle_start) // self.period_s)
        return self.code[index] if 0 <= index < CODE_LENGTH else BLACK

    def restart_at_black(self, code: Sequence[str], now: float) -> None:
        """Show black from now, then the new code: no cycle mixes two codes."""
        self.code = tuple(code)
        self.cycle_start = now - CODE_LENGTH * self.period_s


class LightBuoy(Node):
    def __init__(self, *, context=None, colours: Sequence[str] = DEFAULT_COLOURS, period_s: float = 1.0,
                 black_s: float | None = None, rate_hz: float = 10.0, drop: float = 0.0, noise: float = 0.0,
                 new_code_every: int = 0, seed: int | None = None, topic: str = "light_sequence",
                 answer_topic: str = "light_buoy/answer", request_topic: str = "light_buoy/new_code",
                 namespace: str = "/"):
        super().__init__("light_buoy", namespace=namespace, context=context)
        # Which buoy a printed line is about, when several boats run: " (/boat)"; nothing at the root.
        self._whose = "" if namespace == "/" else f" ({namespace})"
        self.colours = parse_colours(colours)
        self.rng = random.Random(seed)
        self.drop, self.noise, self.new_code_every = drop, noise, new_code_every
        self.sent = self.dropped = self.misread = 0
        self.light_pub = self.create_publisher(String, topic, qos.profile("default"))
        self.answer_pub = self.create_publisher(String, answer_topic, qos.profile("latched"))
        self.create_subscription(Empty, request_topic, self._on_request, qos.profile("default"))
        self.clock = BuoyClock(random_code(self.rng, self.colours), period_s,
                               period_s if black_s is None else black_s, time.monotonic())
        self._announced = False
        self._publish_answer()
        self.create_timer(1.0 / rate_hz, self._tick)

    def _publish_answer(self) -> None:
        self.answer_pub.publish(String(data=",".join(self.clock.code)))
        self._announced = False  # printed from the timer: nothing may print before "simulator running"

    def _new_code(self, now: float) -> None:
        self.clock.restart_at_black(random_code(self.rng, self.colours, avoid=self.clock.code), now)
        self._publish_answer()

    def _on_request(self, _msg) -> None:
        self._new_code(time.monotonic())

    def _tick(self) -> None:
        now = time.monotonic()
        if not self._announced:
            print(f"light buoy code: {','.join(self.clock.code)}{self._whose}", flush=True)
            self._announced = True
        before = self.clock.cycles
        self.clock.advance(now)
        if self.new_code_every and self.clock.cycles // self.new_code_every > before // self.new_code_every:
            self._new_code(now)
        colour = self.clock.light(now)
        if self.drop and self.rng.random() < self.drop:
            self.dropped += 1
            return
        text = colour
        if self.noise and self.rng.random() < self.noise:
            text = self.rng.choice([c for c in self.colours if c != colour] + [BLACK, *MISREADINGS])
            if text == colour:
                text = "purple"
            self.misread += 1
        self.light_pub.publish(String(data=text))
        self.sent += 1

    def destroy_node(self) -> None:
        print(f"light buoy stopped{self._whose}: {self.sent} sent, {self.dropped} dropped, {self.misread} misread",
              flush=True)
        super().destroy_node()


def _probability(text: str) -> float:
    value = float(text)
    if not 0.0 <= value < 1.0:
        raise argparse.ArgumentTypeError(f"{text} is not a probability from 0 up to (not including) 1")
    return value


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0.0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{text} must be a positive number")
    return value


def _colours(text: str) -> tuple[str, ...]:
    try:
        return parse_colours(text.split(","))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("light buoy (Scan the Code)")
    group.add_argument("--buoy-colours", type=_colours, default=DEFAULT_COLOURS, metavar="A,B,...",
                       help="colours codes are made of (default red,green,blue,yellow)")
    group.add_argument("--buoy-period", type=_positive, default=1.0, metavar="S",
                       help="seconds each colour shows (default 1, as in the task)")
    group.add_argument("--buoy-black", type=_positive, default=None, metavar="S",
                       help="seconds of black between codes (default: the period)")
    group.add_argument("--buoy-rate", type=_positive, default=10.0, metavar="HZ",
                       help="messages per second while a light is on, like a camera detector (default 10)")
    group.add_argument("--buoy-drop", type=_probability, default=0.0, metavar="P",
                       help="probability that a message is not sent (default 0)")
    group.add_argument("--buoy-noise", type=_probability, default=0.0, metavar="P",
                       help="probability that a message is a misreading: another colour, black or garbage (default 0)")
    group.add_argument("--buoy-new-code-every", type=int, default=0, metavar="N",
                       help="choose a new code every N cycles (default 0: only on request)")
    group.add_argument("--buoy-seed", type=int, default=None, help="random seed, for repeatable codes and drops")
    group.add_argument("--buoy-topic", default="light_sequence",
                       help="topic the colours go to (default light_sequence, in the robot's namespace)")


def from_arguments(args: argparse.Namespace, context, namespace: str = "/", east_offset_m: float = 0.0) -> LightBuoy:
    return LightBuoy(context=context, colours=args.buoy_colours, period_s=args.buoy_period,
                     black_s=args.buoy_black, rate_hz=args.buoy_rate, drop=args.buoy_drop, noise=args.buoy_noise,
                     new_code_every=max(0, args.buoy_new_code_every), seed=args.buoy_seed, topic=args.buoy_topic,
                     namespace=namespace)


def main(argv: list[str] | None = None) -> None:
    from .runner import run_part
    run_part(sys.modules[__name__], argv)


if __name__ == "__main__":
    main()
