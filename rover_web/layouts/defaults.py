"""The layouts the first start creates: one per robot kind, and "Everything" for a robot of no kind.

Each robot's database gets all four, so a team can switch; the robot's own kind decides which one a
user sees before choosing (store.py `active`). Every one keeps the Drive and Robot cards: whoever
opens a robot's page expects to be able to drive it and to see its battery.
"""

from __future__ import annotations

from rover_web.i18n import N_

from .schema import VERSION


def _card(type_: str, x: int, y: int, w: int, h: int, **settings) -> dict:
    return {"type": type_, "x": x, "y": y, "w": w, "h": h, "settings": settings}


DEFAULTS: dict[str, dict] = {
    # A RobotX boat: the camera, the GPS map and Scan the Code large.
    "boat": {"version": VERSION, "name": N_("Boat"), "cards": [
        _card("camera", 0, 0, 7, 6), _card("drive", 7, 0, 5, 7),
        _card("gps_map", 0, 6, 7, 7), _card("scan_the_code", 7, 7, 5, 6),
        _card("robot", 0, 13, 4, 3), _card("link", 4, 13, 8, 3)]},
    # A campus delivery rover: LiveMap and the drive card.
    "rover": {"version": VERSION, "name": N_("Rover"), "cards": [
        _card("livemap", 0, 0, 6, 6), _card("drive", 6, 0, 6, 7),
        _card("camera", 0, 6, 6, 5), _card("robot", 6, 7, 6, 3),
        _card("diagnostics", 0, 11, 6, 4), _card("link", 6, 10, 6, 3)]},
    # A drone lab: the mission panel, the camera and the battery.
    "drone": {"version": VERSION, "name": N_("Drone"), "cards": [
        _card("panel", 0, 0, 5, 4, panel=""), _card("camera", 5, 0, 7, 6),
        _card("robot", 0, 4, 5, 3), _card("drive", 0, 7, 5, 7),
        _card("gps_map", 5, 6, 7, 7), _card("link", 0, 14, 12, 3)]},
    # No kind given (ROVER_WEB_ROBOTS unset): every card the dashboard has always shown.
    "robot": {"version": VERSION, "name": N_("Everything"), "cards": [
        _card("drive", 0, 0, 4, 7), _card("robot", 4, 0, 4, 3), _card("camera", 8, 0, 4, 6),
        _card("panel", 4, 3, 4, 4, panel=""), _card("gps_map", 0, 7, 8, 7),
        _card("scan_the_code", 8, 6, 4, 7), _card("livemap", 0, 14, 4, 4),
        _card("diagnostics", 4, 14, 4, 4), _card("node", 8, 14, 4, 4), _card("link", 0, 18, 12, 3)]},
}
