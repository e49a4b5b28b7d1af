"""HTTP requests counted by route template and status, for /metrics.

The hook runs on every request, so it is one lock and one dict increment (about a microsecond):
no prometheus Counter child per request. Labels are bounded by construction: the route is
Flask's url_rule.rule (`/api/robots/<name>/history`, never the path asked for; `unmatched` for
a 404 that matched no rule), the method one of the standard ones or `other`, the status a number
Werkzeug produced. The teleop socket and an event stream are one request each, however long
they last, so neither path pays per message.
"""

from __future__ import annotations

import threading

from flask import Flask, request
from prometheus_client.core import CounterMetricFamily

METHODS = frozenset({"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS"})


class RequestCounter:
    def __init__(self):
        self._counts: dict[tuple[str, str, str], int] = {}
        self._lock = threading.Lock()

    @classmethod
    def install(cls, app: Flask) -> RequestCounter:
        counter = cls()
        app.after_request(counter.count)
        return counter

    def count(self, response):
        rule = request.url_rule
        method = request.method if request.method in METHODS else "other"
        key = (rule.rule if rule is not None else "unmatched", method, str(response.status_code))
        with self._lock:
            self._counts[key] = self._counts.get(key, 0) + 1
        return response

    def collect(self):
        family = CounterMetricFamily("rover_web_http_requests", "HTTP requests answered, by route template, "
                                     "method and status", labels=("route", "method", "status"))
        with self._lock:
            counts = sorted(self._counts.items())
        for labels, value in counts:
            family.add_metric(labels, value)
        yield family
