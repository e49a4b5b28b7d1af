"""Recordings: MCAP files of the robot's topics and of the operators' actions (docs/recording.md).

HTTP (routes.py):
  POST   /api/recordings                  start: {"topics": "all" | [names] | "preset:NAME", "camera", "name"}
  GET    /api/recordings                  the list (viewer)
  GET    /api/recordings/<id>             status, live while it runs
  POST   /api/recordings/<id>/stop        stop (operator)
  GET    /api/recordings/<id>/file        download, with HTTP Range
  DELETE /api/recordings/<id>             delete (admin)
  POST   /api/recordings/upload           an MCAP file from elsewhere, to replay (operator)
  GET    /recordings/<id>/replay          the replay view; its data: GET /api/recordings/<id>/timeline,
         .../fields, .../series, .../diagnostics, .../frame (replay_routes.py)
Modules: schema (ros2msg schema text), recorder (the writer thread and the MCAP file), service
(choosing topics, raw subscriptions, the audit trail, limits), store (the SQLite index), reading
(a file whole or cut short), replay (`flask --app rover_web replay FILE`), file_index (a file's
chunk map), timeline and replay_data (the replay view's answers), upload.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rover_web.config import ConfigError
from rover_web.i18n import N_

from .replay import init_cli

if TYPE_CHECKING:
    from rover_web.core.fleet import Fleet

__all__ = ["init_app", "init_cli", "RecordingService", "AUDIT_TOPIC", "recordings_folder"]


def __getattr__(name: str):
    # The service needs rclpy; `flask replay` and the other CLI commands import this package
    # before (and without) ROS, so the service is imported only when asked for.
    if name in ("RecordingService", "AUDIT_TOPIC"):
        from . import service
        return getattr(service, name)
    raise AttributeError(name)


def recordings_folder(app) -> Path:
    configured = app.config.get("ROVER_WEB_RECORDINGS_DIR")
    return Path(configured) if configured else Path(app.instance_path) / "recordings"


def init_app(app, fleet: Fleet) -> None:
    from . import replay_routes, routes  # noqa: F401 - replay_routes adds its routes to routes.bp
    from .service import RecordingService, parse_presets
    from .store import RecordingIndex

    try:
        parse_presets(app.config["ROVER_WEB_RECORDING_PRESETS"])
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    folder = recordings_folder(app)
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"ROVER_WEB_RECORDINGS_DIR: cannot make {folder} ({exc.strerror})") from None
    for rover in fleet:
        # Each robot records its own topics; sign-ins (on the graph-wide hub) go in every robot's file.
        service = RecordingService(rover, folder, RecordingIndex(rover.db), extra_audit=(fleet.graph.audit,))
        rover.add_feature(service)
        rover.on_shutdown(service.shutdown)
        rover.add_nav(N_("Recordings"), "/recordings")
    app.register_blueprint(routes.bp)
