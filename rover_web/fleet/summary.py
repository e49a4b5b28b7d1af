"""One robot's line on the fleet page and in GET /api/robots, read from what its features already
keep (the latest value of each channel), so a fleet view costs nothing per message."""

from __future__ import annotations

from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.teleop.service import TeleopService


def mode(estop: dict, teleop: dict) -> str:
    """What an operator most needs to know first: stopped by the e-stop, driven, or left alone."""
    if estop.get("engaged"):
        return "estop"
    if teleop.get("moving"):
        return "driving"
    if teleop.get("holder"):
        return "operator"
    return "idle"


def summary(rover: Rover, root: str) -> dict:
    robot, hub = rover.robot, rover.hub
    estop = rover.feature(EStopService).state()
    teleop = rover.feature(TeleopService).controller.state()
    status = hub.latest("status") or {}
    odom = hub.latest("odom")
    fix = hub.latest("fix") or {}
    holder = teleop.get("holder")
    return {
        **robot.as_dict(),
        "url": f"{root}/robots/{robot.name}/",
        "link": status.get("robot_link", "no_data"),
        "mode": mode(estop, teleop),
        "operator": holder["name"] if holder else None,
        "speed": {"linear_mps": odom["linear"], "angular_rps": odom["angular"]} if odom else None,
        "battery": hub.latest("battery"),
        "estop": {key: estop.get(key) for key in ("engaged", "since", "by")},
        "position": {"lng": fix["lng"], "lat": fix["lat"]} if fix.get("fix") else None,
    }
