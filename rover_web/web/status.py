"""Link health: GET /api/status and the `status` channel, refreshed by one background thread."""

from __future__ import annotations

import logging
import time

from flask import Blueprint, jsonify

from rover_web.core.state import Rover, current_rover

bp = Blueprint("status", __name__)
log = logging.getLogger(__name__)


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
    # A robot's own topics only: with 20 robots, every status event listing every robot's topics
    # was 24 kB a second to each viewer (BENCHMARKS.md, several robots).
    topics = runtime.topic_stats(config["ROVER_WEB_STALE_AFTER_S"], under=rover.robot.namespace)
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
    """Publish the status every STATUS_PERIOD_S; it is also the pages' heartbeat. When the robot's
    link goes from fresh to stale (its process died, the radio dropped), the link-lost hooks run:
    teleop stops what it holds, so a robot that comes back does not resume an old command."""
    rover.hub.register("status")
    last = {"link": None}

    def report() -> None:
        status = build_status(rover)
        rover.hub.publish("status", status)
        link, before = status["robot_link"], last["link"]
        last["link"] = link
        if link == "stale" and before in ("ok", "degraded"):
            for hook in rover.link_lost_hooks:
                try:
                    hook()
                except Exception:
                    log.exception("a link-lost hook failed")

    report()
    rover.every(rover.config["ROVER_WEB_STATUS_PERIOD_S"], report, name="status-reporter")
