"""HTTP requests counted by route template and status, for /metrics.

The hook runs on every request, so it is one lock and one dict increment (1.3 µs, BENCHMARKS.md):
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
        self._counts: dict[tuple[str, str, int], int] = {}
        self._lock = threading.Lock()

    @classmethod
    def install(cls, app: Flask) -> RequestCounter:
        counter = cls()
        app.after_request(counter.count)
        return counter

    def count(self, response):
        req = request._get_current_object()  # one context lookup, not one per attribute
        rule = req.url_rule
        method = req.method
        key = (rule.rule if rule is not None else "unmatched", method if method in METHODS else "other",
               response.status_code)
        with self._lock:
            self._counts[key] = self._counts.get(key, 0) + 1
        return response

    def collect(self):
        family = CounterMetricFamily("rover_web_http_requests", "HTTP requests answered, by route template, "
                                     "method and status", labels=("route", "method", "status"))
        with self._lock:
            counts = sorted(self._counts.items())
        for (route, method, status), value in counts:
            family.add_metric((route, method, str(status)), value)
        yield family
