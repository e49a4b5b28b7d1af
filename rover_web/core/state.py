"""The one per-app object every feature shares, kept in app.extensions["rover_web"].

Features keep their own per-app object (a service) in it too, keyed by class:
`rover.add_feature(service)` in the feature's init_app, `rover.feature(ServiceClass)` to reach it.
One convention, one typed lookup, and a clear error when a feature was never set up.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from flask import current_app, has_request_context, request

from rover_web.core.loops import Loop, every
from rover_web.core.robots import Robot
from rover_web.core.streams import StreamLimit
from rover_web.events.audit import AuditHub
from rover_web.i18n import N_

if TYPE_CHECKING:
    from rover_web.events.broadcast import Broadcaster
    from rover_web.events.hub import EventHub
    from rover_web.ros.cmd_vel import CmdVelOutput
    from rover_web.ros.runtime import RosRuntime
    from rover_web.storage.db import Database

log = logging.getLogger(__name__)

EXTENSION = "rover_web"
ROBOT_ENVIRON = "rover_web.robot"  # set by rover_web/fleet/prefix.py
LOOP_JOIN_S = 2.0

T = TypeVar("T")


class Robots(Protocol):
    """What a robot needs of the Fleet that holds it (core/fleet.py): its siblings and the graph
    scope. A protocol, so this module does not import the one that imports it."""

    graph: Rover
    names: list[str]

    def __iter__(self) -> Iterator[Rover]: ...
    def get(self, name: str) -> Rover | None: ...
    def shutdown(self) -> None: ...
    def zero_all(self) -> None: ...


class NotSetUp(RuntimeError):
    """A feature (or rover_web itself) was used on an app it was never set up on."""


@dataclass(order=True)
class DashboardPanel:
    """A partial template the dashboard includes, in `order`; features register their own."""

    order: int
    template: str
    title: str = field(compare=False, default="")
    channels: tuple[str, ...] = field(compare=False, default=())


class Rover:
    """One robot (or, as a Fleet's `graph`, the graph-wide scope): its settings, hub and features."""

    def __init__(self, config: dict[str, Any], hub: EventHub, runtime: RosRuntime, cmd_vel: CmdVelOutput | None,
                 db: Database, broadcaster: Broadcaster, *, robot: Robot | None = None,
                 streams: StreamLimit | None = None, nav_links: list[tuple[str, str]] | None = None):
        self.config = config
        self.hub = hub
        self.runtime = runtime
        self.cmd_vel = cmd_vel
        self.db = db
        self.broadcaster = broadcaster  # writes every SSE stream
        self.robot = robot or Robot("robot")
        self.audit = AuditHub(self.robot.name)  # operator actions, for recordings (events/audit.py)
        self.fleet: Robots | None = None  # set by the Fleet that holds this robot
        # SSE, MJPEG, echo and teleop sockets: one limit for the process, shared by every robot.
        self.streams = streams or StreamLimit(config["ROVER_WEB_MAX_STREAMS"])
        self.dashboard_panels: list[DashboardPanel] = []
        # Every robot has the same features, so one list of links serves them all.
        self.nav_links: list[tuple[str, str]] = [(N_("Dashboard"), "/")] if nav_links is None else nav_links
        self._features: dict[type, object] = {}
        self._loops: list[Loop] = []
        self.link_lost_hooks: list[Callable[[], None]] = []
        self._shutdown_hooks: list[Callable[[], None]] = []
        self._stopping = threading.Event()

    @property
    def stopping(self) -> threading.Event:
        """Set once shutdown starts; background loops of features watch it."""
        return self._stopping

    # --- features ---

    def add_feature(self, service: object) -> None:
        """Keep a feature's per-app object; routes reach it with feature(type(service))."""
        if type(service) in self._features:
            raise RuntimeError(f"{type(service).__name__} is set up twice on this app")
        self._features[type(service)] = service

    def feature(self, cls: type[T]) -> T:
        found = self._features.get(cls)
        if found is None and self.fleet is not None and self.fleet.graph is not self:
            found = self.fleet.graph._features.get(cls)  # a graph-wide feature, shared by every robot
        if found is None:
            package = cls.__module__.rsplit(".", 1)[0]
            raise NotSetUp(f"{cls.__name__} is not set up on this app: did you forget "
                           f"{package}.init_app(app, rover) in create_app?")
        return found  # type: ignore[return-value]

    def add_panel(self, order: int, template: str, title: str = "", channels: tuple[str, ...] = ()) -> None:
        """Show `template` on the dashboard; `channels` are the SSE channels its script listens to."""
        self.dashboard_panels.append(DashboardPanel(order, template, title, tuple(channels)))
        self.dashboard_panels.sort()

    def add_nav(self, label: str, href: str) -> None:
        if (label, href) not in self.nav_links:  # each robot's features add the same links
            self.nav_links.append((label, href))

    def resolve(self, name: str) -> str:
        """A ROS name from a feature's own files (a panel's topic) under this robot's namespace."""
        return self.robot.resolve(name)

    # --- background work and shutdown ---

    def every(self, period_s: float, fn: Callable[[], object], *, name: str, immediately: bool = False,
              only_while: threading.Event | None = None) -> Loop:
        """A background loop that ends when the app shuts down, and is joined then."""
        loop = every(period_s, fn, name=name, stopping=self._stopping, immediately=immediately,
                     only_while=only_while)
        self._loops.append(loop)
        return loop

    def on_link_lost(self, hook: Callable[[], None]) -> None:
        """Called (on the status loop) when the robot's link goes from fresh to stale."""
        self.link_lost_hooks.append(hook)

    def on_shutdown(self, hook: Callable[[], None]) -> None:
        """Feature clean-up (threads, databases) that runs after motion is stopped."""
        self._shutdown_hooks.append(hook)

    def shutdown(self) -> None:
        """Ordered stop: robot to zero, event streams ended, loops joined, features, then ROS.

        Any robot's shutdown is the whole process's: every robot of its fleet stops with it."""
        if self.fleet is not None:
            self.fleet.shutdown()
            return
        if self._stopping.is_set():
            return
        self.halt()
        self.wind_down()
        self.runtime.stop(self.config["ROVER_WEB_SHUTDOWN_TIMEOUT_S"])

    def halt(self) -> None:
        """The first step of shutdown: stop the loops' work and publish a zero velocity."""
        self._stopping.set()
        if self.cmd_vel is None:
            return
        try:
            self.cmd_vel.halt()
        except Exception:
            log.exception("could not publish the final zero velocity")

    def wind_down(self) -> None:
        """After every robot halted: end event streams, join loops, run the features' hooks."""
        self.hub.close()
        for loop in self._loops:
            if not loop.join(LOOP_JOIN_S):
                log.warning("background loop %r did not end within %.1f s", loop.name, LOOP_JOIN_S)
        for hook in reversed(self._shutdown_hooks):
            try:
                hook()
            except Exception:
                log.exception("shutdown hook %r failed", hook)


def rover_of(app) -> Rover:
    """The app's Rover, outside a request too (the demo, gunicorn's hooks, tests)."""
    rover = app.extensions.get(EXTENSION)
    if rover is None:
        raise NotSetUp("this Flask app has no rover_web state: build it with rover_web.create_app()")
    return rover


def current_rover() -> Rover:
    """The robot the request is for: /robots/<name>/... names it, any other path is the first's."""
    rover = rover_of(current_app)
    if rover.fleet is None or not has_request_context():
        return rover
    name = request.environ.get(ROBOT_ENVIRON)
    return (rover.fleet.get(name) or rover) if name else rover


def current_feature(cls: type[T]) -> T:
    """The feature object of the app handling the current request."""
    return current_rover().feature(cls)
