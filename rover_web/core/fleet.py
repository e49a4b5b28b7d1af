"""The robots one rover_web serves (ROVER_WEB_ROBOTS), and the graph-wide scope they share.

Each robot is a Rover of its own: its namespace's topics, its own event hub, database, velocity
output, e-stop, deadman and operator. Features that look at the whole ROS graph (the topic
browser, /rosout, plots, parameters and services) are set up once, on `graph`, and every robot
finds them there. With one robot, `graph` is that robot: nothing changes for a one-robot setup.

All robots share one rclpy node and one executor thread: a robot adds subscriptions, not threads
spinning ROS (docs/scaling.md has what that costs per robot).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rover_web.core.state import Rover
    from rover_web.events.hub import EventHub
    from rover_web.ros.runtime import RosRuntime

log = logging.getLogger(__name__)


class FleetHub:
    """The graph scope's hub: a graph-wide channel (topics, rosout, plot) is on every robot's
    stream, so a page of any robot sees it. Publishing costs one append per robot."""

    def __init__(self, hubs: list[EventHub]):
        self._hubs = hubs

    def register(self, *channels: str) -> None:
        for hub in self._hubs:
            hub.register(*channels)

    def publish(self, channel: str, data: Any) -> None:
        for hub in self._hubs:
            hub.publish(channel, data)

    def emit(self, channel: str, data: Any) -> None:
        # A forwarder: the channel is named by the caller (tests/unit/events/test_ring_channels.py
        # checks the callers, `….hub.emit(CHANNEL, …)`).
        for each in self._hubs:
            each.emit(channel, data)

    def latest(self, channel: str) -> Any:
        return self._hubs[0].latest(channel)

    @property
    def channels(self) -> frozenset[str]:
        return self._hubs[0].channels

    @property
    def client_count(self) -> int:
        return sum(hub.client_count for hub in self._hubs)

    def close(self) -> None:
        for hub in self._hubs:
            hub.close()


class Fleet:
    def __init__(self, robots: list[Rover], runtime: RosRuntime, graph: Rover | None = None):
        self.robots = robots
        self.runtime = runtime
        self.graph = graph or robots[0]
        self._by_name = {rover.robot.name: rover for rover in robots}
        self._stopped = False
        self._lock = threading.Lock()
        for rover in {id(r): r for r in [*robots, self.graph]}.values():
            rover.fleet = self

    def __iter__(self) -> Iterator[Rover]:
        return iter(self.robots)

    def __len__(self) -> int:
        return len(self.robots)

    @property
    def first(self) -> Rover:
        return self.robots[0]

    def get(self, name: str) -> Rover | None:
        return self._by_name.get(name)

    @property
    def names(self) -> list[str]:
        return [rover.robot.name for rover in self.robots]

    def zero_all(self) -> None:
        """A zero velocity to every robot now (a signal's first act); the ordered stop comes later."""
        for rover in self.robots:
            try:
                rover.cmd_vel.halt()
            except Exception:
                log.exception("could not stop robot %s", rover.robot.name)

    def shutdown(self) -> None:
        """Every robot to zero first, then the graph's work, each robot's, and ROS last."""
        with self._lock:
            if self._stopped:
                return
            self._stopped = True
        for rover in self.robots:
            rover.halt()
        if self.graph not in self.robots:
            self.graph.halt()
            self.graph.wind_down()  # graph features may write the first robot's database: before it closes
        for rover in reversed(self.robots):
            rover.wind_down()
        self.runtime.stop(self.first.config["ROVER_WEB_SHUTDOWN_TIMEOUT_S"])
