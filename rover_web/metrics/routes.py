"""GET /metrics: the app's registry written in the Prometheus text format."""

from __future__ import annotations

from flask import Blueprint, Response, current_app
from prometheus_client import CONTENT_TYPE_LATEST, generate_latest

EXTENSION = "rover_web_metrics"

bp = Blueprint("metrics", __name__)


@bp.get("/metrics")
def metrics():
    registry = current_app.extensions[EXTENSION]
    return Response(generate_latest(registry), headers={"Content-Type": CONTENT_TYPE_LATEST,
                                                        "Cache-Control": "no-store"})
