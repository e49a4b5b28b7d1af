"""The one per-app object every feature shares, kept in app.extensions["rover_web"].

Features keep their own per-app object (a service) in it too, keyed by class:
`rover.add_feature(service)` in the feature's init_app, `rover.feature(ServiceClass)` to reach it.
One convention, one typed lookup, and a clear error when a feature was never set up.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeVar

from flask import current_app

from rover_web.core.loops import Loop, every
from rover_web.core.streams import StreamLimit

if TYPE_CHECKING:
    from rover_web.events.broadcast import Broadcaster
    from rover_web.events.hub import EventHub
    from rover_web.ros.cmd_vel import CmdVelOutput
    from rover_web.ros.runtime import RosRuntime
    from rover_web.storage.db import Database

log = logging.getLogger(__name__)

EXTENSION = "rover_web"
LOOP_JOIN_S = 2.0

T = TypeVar("T")


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
    def __init__(self, config: dict[str, Any], hub: EventHub, runtime: RosRuntime, cmd_vel: CmdVelOutput,
                 db: Database, broadcaster: Broadcaster):
        self.config = config
        self.hub = hub
        self.runtime = runtime
        self.cmd_vel = cmd_vel
        self.db = db
        self.broadcaster = broadcaster  # writes every SSE stream
        self.streams = StreamLimit(config["ROVER_WEB_MAX_STREAMS"])  # SSE, MJPEG, echo and teleop sockets
        self.dashboard_panels: list[DashboardPanel] = []
        self.nav_links: list[tuple[str, str]] = [("Dashboard", "/")]
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
        try:
            return self._features[cls]  # type: ignore[return-value]
        except KeyError:
            package = cls.__module__.rsplit(".", 1)[0]
            raise NotSetUp(f"{cls.__name__} is not set up on this app: did you forget "
                           f"{package}.init_app(app, rover) in create_app?") from None

    def add_panel(self, order: int, template: str, title: str = "", channels: tuple[str, ...] = ()) -> None:
        """Show `template` on the dashboard; `channels` are the SSE channels its script listens to."""
        self.dashboard_panels.append(DashboardPanel(order, template, title, tuple(channels)))
        self.dashboard_panels.sort()

    def add_nav(self, label: str, href: str) -> None:
        self.nav_links.append((label, href))

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
        """Ordered stop: robot to zero, event streams ended, loops joined, features, then ROS."""
        if self._stopping.is_set():
            return
        self._stopping.set()
        try:
            self.cmd_vel.halt()
        except Exception:
            log.exception("could not publish the final zero velocity")
        self.hub.close()
        for loop in self._loops:
            if not loop.join(LOOP_JOIN_S):
                log.warning("background loop %r did not end within %.1f s", loop.name, LOOP_JOIN_S)
        for hook in reversed(self._shutdown_hooks):
            try:
                hook()
            except Exception:
                log.exception("shutdown hook %r failed", hook)
        self.runtime.stop(self.config["ROVER_WEB_SHUTDOWN_TIMEOUT_S"])


def rover_of(app) -> Rover:
    """The app's Rover, outside a request too (the demo, gunicorn's hooks, tests)."""
    rover = app.extensions.get(EXTENSION)
    if rover is None:
        raise NotSetUp("this Flask app has no rover_web state: build it with rover_web.create_app()")
    return rover


def current_rover() -> Rover:
    return rover_of(current_app)


def current_feature(cls: type[T]) -> T:
    """The feature object of the app handling the current request."""
    return current_rover().feature(cls)
