"""Every robot's e-stop at once: POST /api/estop/all, and the gate for graph-wide commands.

A service call or an action goal sent from the ROS page cannot be traced to one robot, so it is
refused while any robot's e-stop is engaged, and any engage cancels the goals it sent.
"""

from __future__ import annotations

from collections.abc import Callable

from .service import EStopService


class FleetEStop:
    def __init__(self, robots: dict[str, EStopService]):
        self.robots = robots  # robot name -> its e-stop, in the order of ROVER_WEB_ROBOTS

    @property
    def engaged(self) -> bool:
        return any(estop.engaged for estop in self.robots.values())

    def check_motion(self) -> None:
        """Raise EStopEngaged with the first engaged robot's latch."""
        for estop in self.robots.values():
            estop.check_motion()

    def on_engage(self, hook: Callable[[str], None]) -> None:
        for estop in self.robots.values():
            estop.on_engage(hook)

    def engage_all(self, by: str, via: str = "api") -> dict[str, dict]:
        """Engage each robot's e-stop; each one's zero velocity goes out before its latch is stored."""
        return {name: estop.engage(by, via=via) for name, estop in self.robots.items()}
