"""Several simulated robots in one process: `--robots boat,rover2,alpha:drone`. Pure Python.

Each robot lives in namespace `/<name>`, and its kind decides which simulator parts it runs. The
kind is written `name:kind`, or taken from the name when it starts with a kind (`boat`, `rover2`,
`drone_a`); anything else is a rover.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field

from rover_web.core import robots as robots_setting

# Which parts each kind runs, in the order they start.
KIND_PARTS: dict[str, tuple[str, ...]] = {
    "boat": ("rover", "light_buoy"),  # a diff-drive hull with GPS, and the buoy it scans
    "rover": ("rover", "camera"),
    "drone": ("drone", "camera"),
}
DEFAULT_KIND = "rover"
# Robots that drive (run the rover part) start this far east of each other, so they are apart on the map.
SPACING_EAST_M = 20.0


@dataclass(frozen=True)
class Robot:
    name: str
    kind: str

    @property
    def namespace(self) -> str:
        return "/" + self.name

    @property
    def parts(self) -> tuple[str, ...]:
        return KIND_PARTS[self.kind]


def kind_from_name(name: str) -> str:
    """The app's rule (ROVER_WEB_ROBOTS's short form), so both name a robot's kind alike."""
    kind = robots_setting.kind_from_name(name)
    return kind if kind in KIND_PARTS else DEFAULT_KIND


def parse_robot(text: str) -> Robot:
    name, sep, kind = text.strip(" ").partition(":")
    if not robots_setting.NAME_PATTERN.match(name):
        raise ValueError(f"robot name {name!r} must be lower-case letters, digits and _, starting with a letter")
    if not sep:
        return Robot(name, kind_from_name(name))
    if kind not in KIND_PARTS:
        raise ValueError(f"robot {name!r}: unknown kind {kind!r} (known: {', '.join(KIND_PARTS)})")
    return Robot(name, kind)


def parse_robots(text: str) -> list[Robot]:
    robots = [parse_robot(item) for item in text.split(",")]
    seen: set[str] = set()
    for robot in robots:
        if robot.name in seen:
            raise ValueError(f"robot {robot.name!r} is named twice")
        seen.add(robot.name)
    return robots


def robots_argument(text: str) -> list[Robot]:
    """argparse `type=`: a clear usage error instead of a traceback."""
    try:
        return parse_robots(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


@dataclass(frozen=True)
class Placement:
    """One part of one robot: where its node lives and, for the n-th driving robot, how far east it starts."""
    part: str
    namespace: str
    east_offset_m: float
    kind: str = field(default="", compare=False)  # a boat is on water: no floorplan walls for it


def plan(robots: list[Robot], only: list[str] | None = None) -> list[Placement]:
    """Every (robot, part) to run; `only` keeps just those parts within each robot."""
    placements: list[Placement] = []
    drivers = 0
    for robot in robots:
        for part in robot.parts:
            if only and part not in only:
                continue
            offset = 0.0
            if part == "rover":
                offset = drivers * SPACING_EAST_M
                drivers += 1
            placements.append(Placement(part, robot.namespace, offset, robot.kind))
    return placements
