"""The robot's link to a fleet hub over Zenoh (off by default: ROVER_WEB_ZENOH_MODE).

  Zenoh rover_web/<fleet>/<robot>/summary  each robot's summary, signed, ~1 Hz and on change
  Zenoh rover_web/<fleet>/<robot>/alive    its liveliness token
  Zenoh rover_web/<fleet>/<robot>/stop     queryable: the hub's signed stop engages its e-stop
No HTTP route. Modules: session (settings, key expressions, the session), signing (HMAC and the
replay guard), robot (the link itself). The hub's side is rover_web/hub. docs/fleet.md#a-hub-over-zenoh.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet

from .session import link_settings, own_url

__all__ = ["init_app", "check_settings"]


def check_settings(settings: dict) -> None:
    """Before anything starts: with Zenoh on, no proof configured (a key file) is a ConfigError."""
    link_settings(settings)


def init_app(fleet: Fleet) -> None:
    """After the e-stop is set up (the stop queryable engages it); the loop starts with the app's."""
    settings = fleet.first.config
    link = link_settings(settings)
    if link is None:
        return
    from .robot import TICK_S, RobotLink

    robot_link = RobotLink(fleet, link, own_url(settings), settings["ROVER_WEB_FLEET_COMMAND_WINDOW_S"])
    fleet.first.every(TICK_S, robot_link.tick, name="zenoh-link", immediately=True)
    fleet.first.on_shutdown(robot_link.close)
    fleet.first.add_feature(robot_link)
