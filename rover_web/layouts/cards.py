"""The cards a layout may hold: what each shows, its settings (as JSON Schema) and its limits. Pure.

A card that reuses a feature's dashboard panel names that panel's template: its SSE channels are
the ones the feature registered with `rover.add_panel` (core/state.py), so the page subscribes to
exactly what its cards need. Cards whose partial and script find their elements by id may appear
once per layout (`once`); plot, echo and logs cards find theirs from the card element, so a layout
may hold several.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rover_web.i18n import N_

# The end of the string, in a JSON Schema (ECMA) pattern that Python's re reads the same: `$` alone
# also matches before a trailing newline in Python, so {"topic": "/a\n"} was stored (issue 40), and
# ECMA has no \Z. "Nothing follows" is a negative lookahead on any character.
END = r"(?![\s\S])"
# The rules of a fully qualified ROS topic name (web/validate.py topic_name), as a JSON Schema pattern.
TOPIC = {"type": "string", "maxLength": 247, "pattern": r"^(/[A-Za-z_][A-Za-z0-9_]*)+" + END}
TOPIC_OR_DEFAULT = {"type": "string", "maxLength": 247, "pattern": r"^((/[A-Za-z_][A-Za-z0-9_]*)+)?" + END,
                    "description": "\"\" for the robot's configured topic"}
FIELD_PATH = {"type": "string", "minLength": 1, "maxLength": 200, "pattern": r"^[A-Za-z0-9_.\[\]]+" + END}
LEVELS = ["DEBUG", "INFO", "WARN", "ERROR", "FATAL"]


def settings(properties: dict[str, Any] | None = None, required: tuple[str, ...] = ()) -> dict:
    schema: dict[str, Any] = {"type": "object", "properties": properties or {}, "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    return schema


@dataclass(frozen=True)
class CardType:
    name: str
    title: str
    template: str  # the partial the dashboard includes
    settings: dict = field(default_factory=settings)
    once: bool = True  # at most one per layout (its partial finds its elements by id)
    panel: str = ""  # the feature's dashboard panel template whose channels it needs
    channels: tuple[str, ...] = ()  # channels of its own, beside the panel's
    size: tuple[int, int] = (4, 4)  # w, h when added in the editor
    min_size: tuple[int, int] = (2, 2)
    help: str = ""


CARDS: dict[str, CardType] = {c.name: c for c in (
    CardType("drive", N_("Drive"), "panels/teleop.html", panel="panels/teleop.html", size=(4, 7), min_size=(3, 4),
             help=N_("joystick, keys and gamepad")),
    CardType("robot", N_("Robot"), "panels/odom.html", panel="panels/odom.html", size=(4, 3), min_size=(2, 2),
             help=N_("speed, position and battery")),
    CardType("camera", N_("Camera"), "panels/camera.html", panel="panels/camera.html", size=(6, 6), min_size=(3, 3),
             settings=settings({"topic": TOPIC_OR_DEFAULT}), help=N_("any image topic, live or snapshots")),
    CardType("gps_map", N_("GPS map"), "panels/waypoints.html", panel="panels/waypoints.html", size=(8, 7),
             min_size=(4, 4), help=N_("waypoints, the mission and the geofence")),
    CardType("livemap", N_("Live map"), "panels/livemap.html", panel="panels/livemap.html", size=(4, 4),
             help=N_("the floorplan with the robot on it")),
    CardType("scan_the_code", N_("Scan the Code"), "panels/scan_the_code.html", panel="panels/scan_the_code.html",
             size=(4, 6), min_size=(3, 3), help=N_("the light buoy's sequence")),
    CardType("panel", N_("Mission panel"), "panels/panels.html", panel="panels/panels.html", size=(4, 4),
             settings=settings({"panel": {"type": "string", "maxLength": 64, "pattern": r"^([a-z][a-z0-9_-]*)?" + END,
                                          "description": "a panel's id; \"\" for every panel"}}),
             help=N_("a mission control panel's light and status")),
    CardType("plot", N_("Plot"), "cards/plot.html", once=False, channels=("plot",), size=(6, 4), min_size=(3, 3),
             settings=settings({"series": {"type": "array", "minItems": 1, "maxItems": 4,
                                           "items": settings({"topic": TOPIC, "field": FIELD_PATH},
                                                             ("topic", "field"))},
                                "window_s": {"enum": [10, 30, 60, 300]}}, ("series",)),
             help=N_("chosen numeric fields over time")),
    CardType("echo", N_("Topic echo"), "cards/echo.html", once=False, size=(4, 4),
             settings=settings({"topic": TOPIC}, ("topic",)), help=N_("the latest message of a topic")),
    CardType("diagnostics", N_("Diagnostics"), "panels/diagnostics.html", panel="panels/diagnostics.html",
             size=(4, 4), help=N_("the worst level of each piece of hardware")),
    CardType("logs", N_("Logs"), "cards/logs.html", once=False, channels=("rosout",), size=(6, 4), min_size=(3, 2),
             settings=settings({"level": {"enum": LEVELS},
                                "lines": {"type": "integer", "minimum": 5, "maximum": 100}}),
             help=N_("the newest /rosout lines at or above a level")),
    CardType("node", N_("Node"), "cards/node.html", size=(4, 4), help=N_("rover_web's node and its topics")),
    CardType("link", N_("Link"), "cards/link.html", size=(6, 3), min_size=(3, 2),
             help=N_("round trip to the server and the age of the robot's newest message")),
    # One per layout: each is a WebGL context, and browsers allow a page only a few (about 16).
    CardType("view3d", N_("3D view"), "cards/view3d.html", channels=("view3d", "view3d_robot", "view3d_markers"),
             settings=settings({"fixed": {"enum": ["map", "odom", "robot"]}}), size=(6, 6), min_size=(3, 3),
             help=N_("the robot's model moved by TF, its markers and point cloud")),
)}


def catalogue() -> list[dict]:
    """The card types as the editor offers them (the page embeds this as JSON). Title and help are the
    English message ids: the page translates them (web/pages.py)."""
    return [{"name": c.name, "title": c.title, "help": c.help, "settings": c.settings, "once": c.once,
             "size": list(c.size), "min_size": list(c.min_size)} for c in CARDS.values()]
