"""ROVER_WEB_ROBOTS: which robots one rover_web serves, and how each one's ROS names resolve.

Pure data and validation (no Flask, no rclpy), so config.py can check the setting before
anything starts, and the simulator can share the naming rules.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

# A robot's name is a URL path segment and a ROS name token at once.
NAME_PATTERN = re.compile(r"[a-z][a-z0-9_]{0,31}\Z")
NAMESPACE_PATTERN = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+\Z")
KINDS = ("boat", "rover", "drone", "robot")
DEFAULT_NAME = "robot"


class RobotsError(ValueError):
    """ROVER_WEB_ROBOTS is malformed; the message says which robot and why."""


@dataclass(frozen=True)
class Robot:
    name: str
    namespace: str = ""  # "" (no namespace, today's topics) or "/boat"
    kind: str = "robot"
    title: str = ""

    @property
    def label(self) -> str:
        return self.title or self.name

    def resolve(self, name: str) -> str:
        """A configured ROS name under this robot's namespace: "/cmd_vel" -> "/boat/cmd_vel".

        Configured names are written once for every robot, so the absolute ones are meant relative
        to the robot too; a private name ("~/x") belongs to rover_web's node and is left alone.
        """
        if not self.namespace or name.startswith("~"):
            return name
        return f"{self.namespace}/{name.lstrip('/')}"

    def as_dict(self) -> dict[str, str]:
        return {"name": self.name, "namespace": self.namespace, "kind": self.kind, "title": self.label}


def kind_from_name(name: str) -> str:
    """boat, boat2 and drone_a are what they say; anything else is a rover."""
    return next((k for k in KINDS if name.startswith(k)), "rover")


def from_text(text: str) -> Any:
    """The environment form: JSON, or the short form "boat,rover,alpha:drone" (namespace /<name>
    each, the kind after a colon or from the name), as `python -m rover_web.sim --robots` takes it."""
    stripped = text.strip()
    if stripped.startswith("["):
        return stripped  # left to the JSON reader
    robots = []
    for part in (p.strip() for p in stripped.split(",")):
        if part:
            name, colon, kind = part.partition(":")
            robots.append({"name": name.strip(), **({"kind": kind.strip()} if colon else {})})
    return robots


def parse(value: Any) -> list[Robot]:
    """Validate ROVER_WEB_ROBOTS; an empty list is the one robot of old, with no namespace."""
    if not isinstance(value, (list, tuple)):
        raise RobotsError("expected a list of robots such as [{\"name\": \"boat\", \"namespace\": \"/boat\"}]")
    if not value:
        return [Robot(DEFAULT_NAME)]
    robots: list[Robot] = []
    for i, entry in enumerate(value):
        if isinstance(entry, str):
            entry = {"name": entry}
        if not isinstance(entry, dict):
            raise RobotsError(f"robot {i + 1}: expected an object with a name, got {entry!r:.60}")
        unknown = set(entry) - {"name", "namespace", "kind", "title"}
        if unknown:
            raise RobotsError(f"robot {i + 1}: unknown field(s) {', '.join(sorted(unknown))}; "
                              "known: name, namespace, kind, title")
        name = entry.get("name")
        if not isinstance(name, str) or not NAME_PATTERN.match(name):
            raise RobotsError(f"robot {i + 1}: name {name!r:.40} must be 1-32 of a-z, 0-9 and _, "
                              "starting with a letter")
        namespace = entry.get("namespace", f"/{name}")
        if not isinstance(namespace, str) or (namespace and not NAMESPACE_PATTERN.match(namespace)):
            raise RobotsError(f"robot {name}: namespace {namespace!r:.60} must be empty or a ROS "
                              "namespace such as /boat")
        kind = entry.get("kind", kind_from_name(name))
        if kind not in KINDS:
            raise RobotsError(f"robot {name}: kind {kind!r:.20} must be one of {', '.join(KINDS)}")
        title = entry.get("title", "")
        if not isinstance(title, str) or len(title) > 64:
            raise RobotsError(f"robot {name}: title must be text of at most 64 characters")
        robots.append(Robot(name, namespace, kind, title))
    for field in ("name", "namespace"):
        seen: set[str] = set()
        for robot in robots:
            if getattr(robot, field) in seen:
                raise RobotsError(f"two robots have the {field} {getattr(robot, field)!r}")
            seen.add(getattr(robot, field))
    return robots


# Settings that hold ROS names: each robot gets them resolved under its namespace.
NAME_LISTS = ("ROVER_WEB_LINK_TOPICS", "ROVER_WEB_ESTOP_CANCEL_ACTIONS", "ROVER_WEB_COSTMAP_TOPICS")


def settings_for(robot: Robot, settings: dict[str, Any], topic_keys: Iterable[str]) -> dict[str, Any]:
    """The settings one robot's features read: every ROS name resolved under its namespace.

    `topic_keys` are the settings that name one topic (config.TOPIC_KEYS): they are passed in
    because config.py imports this module to check ROVER_WEB_ROBOTS, and not the other way round.
    A robot without a namespace (the one robot of old) reads the settings as they are.
    """
    if not robot.namespace:
        return settings
    mine = dict(settings)
    for key in topic_keys:
        if mine[key]:
            mine[key] = robot.resolve(mine[key])
    for key in NAME_LISTS:
        mine[key] = [robot.resolve(name) for name in mine[key]]
    return mine
