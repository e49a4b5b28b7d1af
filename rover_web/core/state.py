"""The per-app state every feature shares, kept in app.extensions["rover_web"]."""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass, field
from typing import Any, Callable

from flask import current_app

from rover_web.events.hub import EventHub

log = logging.getLogger(__name__)


@dataclass(order=True)
class DashboardPanel:
    """A partial template the dashboard includes, in `order`; features register their own."""

    order: int
    template: str
    title: str = field(compare=False, default="")
    channels: tuple[str, ...] = field(compare=False, default=())


class Rover:
    def __init__(self, config: dict[str, Any], hub: EventHub, runtime, cmd_vel):
        self.config = config
        self.hub = hub
        self.runtime = runtime
        self.cmd_vel = cmd_vel
        self.db = None  # rover_web.db.Database, opened by create_app
        self.broadcaster = None  # rover_web.sse_broadcast.Broadcaster, writes every SSE stream
        self.dashboard_panels: list[DashboardPanel] = []
        self.nav_links: list[tuple[str, str]] = [("Dashboard", "/")]
        self._shutdown_hooks: list[Callable[[], None]] = []
        self._stopping = threading.Event()

    @property
    def stopping(self) -> threading.Event:
        """Set once shutdown starts; background loops of features watch it."""
        return self._stopping

    def add_panel(self, order: int, template: str, title: str = "", channels: tuple[str, ...] = ()) -> None:
        """Show `template` on the dashboard; `channels` are the SSE channels its script listens to."""
        self.dashboard_panels.append(DashboardPanel(order, template, title, tuple(channels)))
        self.dashboard_panels.sort()

    def add_nav(self, label: str, href: str) -> None:
        self.nav_links.append((label, href))

    def on_shutdown(self, hook: Callable[[], None]) -> None:
        """Feature clean-up (threads, databases) that runs after motion is stopped."""
        self._shutdown_hooks.append(hook)

    def shutdown(self) -> None:
        """Ordered stop: robot to zero, event streams ended, features, then the ROS runtime."""
        if self._stopping.is_set():
            return
        self._stopping.set()
        try:
            self.cmd_vel.halt()
        except Exception:
            log.exception("could not publish the final zero velocity")
        self.hub.close()
        for hook in reversed(self._shutdown_hooks):
            try:
                hook()
            except Exception:
                log.exception("shutdown hook %r failed", hook)
        self.runtime.stop(self.config["ROVER_WEB_SHUTDOWN_TIMEOUT_S"])


def current_rover() -> Rover:
    return current_app.extensions["rover_web"]
