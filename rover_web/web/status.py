"""Link health: GET /api/status and the `status` channel, refreshed by one background thread."""

from __future__ import annotations

import time

from flask import Blueprint, jsonify

from rover_web.core.state import Rover, current_rover

bp = Blueprint("status", __name__)


def link_state(topics: list[dict], link_topics: list[str]) -> str:
    """ok: every link topic fresh; degraded: some; stale: none fresh now; no_data: never heard."""
    watched = [t for t in topics if t["topic"] in link_topics]
    if not watched or all(t["count"] == 0 for t in watched):
        return "no_data"
    fresh = sum(1 for t in watched if t["fresh"])
    if fresh == len(link_topics):
        return "ok"
    return "degraded" if fresh else "stale"


def build_status(rover: Rover) -> dict:
    runtime, config = rover.runtime, rover.config
    topics = runtime.topic_stats(config["ROVER_WEB_STALE_AFTER_S"])
    return {
        "node": runtime.node_name,
        "middleware": runtime.middleware,
        "domain_id": runtime.domain_id,
        "uptime_s": round(time.monotonic() - runtime.started_monotonic, 1),
        "ros_ok": runtime.running,
        "callback_errors": runtime.callback_errors,
        "stale_after_s": config["ROVER_WEB_STALE_AFTER_S"],
        "link_topics": config["ROVER_WEB_LINK_TOPICS"],
        "robot_link": link_state(topics, config["ROVER_WEB_LINK_TOPICS"]),
        "sse_clients": rover.hub.client_count,
        "streams": rover.streams.snapshot(),
        "topics": topics,
    }


@bp.get("/api/ping")
def ping():
    """The smallest answer, for the browser to time its round trip to the server (the link plot)."""
    return jsonify({"t": round(time.time(), 4)})


@bp.get("/api/status")
def status():
    return jsonify(build_status(current_rover()))


def start_reporter(rover: Rover) -> None:
    """Publish the status every STATUS_PERIOD_S; it is also the pages' heartbeat."""
    rover.hub.register("status")
    rover.hub.publish("status", build_status(rover))
    rover.every(rover.config["ROVER_WEB_STATUS_PERIOD_S"], lambda: rover.hub.publish("status", build_status(rover)),
                name="status-reporter")
