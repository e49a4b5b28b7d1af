"""Every robot's e-stop at once: POST /api/estop/all, and the gate for graph-wide commands.

A service call or an action goal sent from the ROS page cannot be traced to one robot, so it is
refused while any robot's e-stop is engaged, and any engage cancels the goals it sent.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from rover_web.core.rate_limit import RateLimit

from .service import EStopService

PUBLIC_ENGAGES_PER_MIN = 6  # from the sign-in page, per client address


class FleetEStop:
    def __init__(self, robots: dict[str, EStopService]):
        self.robots = robots  # robot name -> its e-stop, in the order of ROVER_WEB_ROBOTS
        self.public_engages = RateLimit(PUBLIC_ENGAGES_PER_MIN, 60.0)  # POST /login/estop, by address

    @property
    def engaged(self) -> bool:
        return any(estop.engaged for estop in self.robots.values())

    @property
    def all_engaged(self) -> bool:
        return all(estop.engaged for estop in self.robots.values())

    def check_motion(self) -> None:
        """Raise EStopEngaged with the first engaged robot's latch."""
        for estop in self.robots.values():
            estop.check_motion()

    def on_engage(self, hook: Callable[[str], None]) -> None:
        for estop in self.robots.values():
            estop.on_engage(hook)

    def engage_all(self, by: str, via: str = "api") -> dict[str, dict]:
        """Engage each robot's e-stop at once, on a thread each.

        An engage sends the robot's zero velocity first, then stores the latch (an fsync on that
        robot's database). One after another, the last robot would wait for every other robot's
        fsync before its zero went out; side by side, every zero goes out at once.
        """
        if len(self.robots) == 1:
            return {name: estop.engage(by, via=via) for name, estop in self.robots.items()}
        with ThreadPoolExecutor(max_workers=len(self.robots), thread_name_prefix="estop-all") as pool:
            futures = {name: pool.submit(estop.engage, by, via) for name, estop in self.robots.items()}
        return {name: future.result() for name, future in futures.items()}
