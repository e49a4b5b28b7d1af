"""The hub's /metrics: each robot as the hub hears it (label `robot`), the fleet's counts, and the
stop-all answers by result. Read from the directory at scrape time (rover_web/metrics).

Robot names come from Zenoh key expressions, so they are bounded by the directory (MAX_ROBOTS,
names of a-z 0-9 _ only) and forgotten robots leave the scrape with the list.
"""

from __future__ import annotations

import math
import threading
from collections import Counter

from prometheus_client.core import CounterMetricFamily, GaugeMetricFamily

from .directory import STATES

LINK_STATES = ("ok", "degraded", "stale", "no_data")
RESULTS = ("engaged", "not_engaged", "refused", "no_answer", "bad_answer", "error")


def _number(value) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value) else None


class StopAnswers:
    """Stop-all answers counted by result, since the hub started."""

    def __init__(self):
        self.counts: Counter[str] = Counter()
        self._lock = threading.Lock()

    def add(self, result: dict) -> None:
        with self._lock:
            for answer in result["robots"].values():
                self.counts[answer["result"] if answer["result"] in RESULTS else "error"] += 1

    def snapshot(self) -> dict[str, int]:
        with self._lock:
            return dict(self.counts)


class HubCollector:
    def __init__(self, hub):
        self.hub = hub

    def collect(self):
        directory = self.hub.directory
        alive = GaugeMetricFamily("rover_web_hub_robot_alive", "1 while the robot's liveliness token is there",
                                  labels=("robot",))
        heard = GaugeMetricFamily("rover_web_hub_robot_state", "1 for the state the hub hears the robot in "
                                  "(waiting, live, lost)", labels=("robot", "state"))
        age = GaugeMetricFamily("rover_web_hub_summary_age_seconds", "Since the robot's last authentic summary",
                                labels=("robot",))
        estop = GaugeMetricFamily("rover_web_hub_estop_engaged", "1 while the robot reports its e-stop engaged",
                                  labels=("robot",))
        percent = GaugeMetricFamily("rover_web_hub_battery_percent", "The robot's battery, as it reports it",
                                    labels=("robot",))
        volts = GaugeMetricFamily("rover_web_hub_battery_voltage_volts", "The robot's battery voltage",
                                  labels=("robot",))
        link = GaugeMetricFamily("rover_web_hub_robot_link", "The robot's own link state: 1 for the current one",
                                 labels=("robot", "state"))
        for line in directory.robots():
            name = line["name"]
            alive.add_metric((name,), 1.0 if line["alive"] else 0.0)
            for state in STATES:
                heard.add_metric((name, state), 1.0 if line["heard"] == state else 0.0)
            if line["summary_age_s"] is not None:
                age.add_metric((name,), line["summary_age_s"])
            engaged = (line.get("estop") or {}).get("engaged") if isinstance(line.get("estop"), dict) else None
            if isinstance(engaged, bool):
                estop.add_metric((name,), 1.0 if engaged else 0.0)
            battery = line.get("battery") if isinstance(line.get("battery"), dict) else {}
            if _number(battery.get("percent")) is not None:
                percent.add_metric((name,), float(battery["percent"]))
            if _number(battery.get("voltage")) is not None:
                volts.add_metric((name,), float(battery["voltage"]))
            for state in LINK_STATES:
                link.add_metric((name, state), 1.0 if line.get("link") == state else 0.0)
        counts = directory.counts()
        robots = GaugeMetricFamily("rover_web_hub_robots", "Robots the hub lists, by state", labels=("state",))
        for state in STATES:
            robots.add_metric((state,), counts[state])
        forgotten = CounterMetricFamily("rover_web_hub_robots_forgotten", "Robots dropped from the list after "
                                        "ROVER_WEB_FLEET_FORGET_AFTER_S lost", value=directory.forgotten_total)
        dropped = CounterMetricFamily("rover_web_hub_summaries_dropped", "Summaries refused, by why",
                                      labels=("reason",))
        dropped.add_metric(("forged",), directory.forged)
        dropped.add_metric(("stale",), directory.stale)
        answers = CounterMetricFamily("rover_web_hub_stop_answers", "Stop-all answers, by result",
                                      labels=("result",))
        given = self.hub.stop_answers.snapshot()
        for result in RESULTS:
            answers.add_metric((result,), given.get(result, 0))
        yield from (alive, heard, age, estop, percent, volts, link, robots, forgotten, dropped, answers)
