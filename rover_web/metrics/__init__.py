"""GET /metrics: the robot's state in the Prometheus text format, for the tools an operations team
already runs (Prometheus, Alertmanager, Grafana); the alerting rules are docs/alerts.yml.

  GET /metrics   every robot's e-stop, operator, battery, link, watched topics, viewers,
                 recording and geofence; the process's CPU, memory, threads, descriptors and HTTP
                 requests by route template and status. On the hub (ROVER_WEB_HUB), each robot
                 as the hub hears it (rover_web/hub/metrics.py) instead of the robot's own.

Made with prometheus-client, by collectors that read what the features already keep when
Prometheus scrapes (one dict lookup per figure): nothing is added to the teleop or event paths
but a counter per HTTP request (http.py). Each app has its own registry (tests build several).
Who may read it is the API's rule (auth/policy.py: a GET, the viewer role when sign-in is on, a
Bearer token for Prometheus); ROVER_WEB_METRICS=off leaves the route out (404).
Label values are bounded: robots from ROVER_WEB_ROBOTS (or the hub's, at most MAX_ROBOTS),
topics the features track (never one a person types), route templates (never paths).
"""

from __future__ import annotations

from flask import Flask
from prometheus_client import CollectorRegistry, ProcessCollector

from .http import RequestCounter
from .process import ThreadsCollector
from .routes import EXTENSION, bp


def _registry(app: Flask, *collectors) -> CollectorRegistry | None:
    if app.config.get("ROVER_WEB_METRICS", "on") == "off":
        return None
    registry = CollectorRegistry(auto_describe=False)
    ProcessCollector(registry=registry)  # process_cpu_seconds_total, _resident_memory_bytes, _open_fds, ...
    registry.register(ThreadsCollector())
    registry.register(RequestCounter.install(app))
    for collector in collectors:
        registry.register(collector)
    app.extensions[EXTENSION] = registry
    app.register_blueprint(bp)
    return registry


def init_app(app: Flask, fleet) -> None:
    """A robot's rover_web: after every feature (the collector reads them) and the fleet's routes."""
    from .robot import RobotCollector

    _registry(app, RobotCollector(fleet))


def init_hub(app: Flask, rover, hub) -> None:
    from rover_web.hub.metrics import HubCollector

    _registry(app, HubCollector(hub))
