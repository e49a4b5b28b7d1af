"""Each robot's figures for /metrics, read at scrape time from what its features keep.

Every family carries the label `robot` (ROVER_WEB_ROBOTS' names: bounded by the setting). A
figure the robot does not have (no battery message yet, a NaN voltage, nobody driving) is left
out rather than written as NaN, so an alert on it never fires on "unknown".
"""

from __future__ import annotations

import logging
import math

from prometheus_client.core import CounterMetricFamily, GaugeMetricFamily

log = logging.getLogger(__name__)

LINK_STATES = ("ok", "degraded", "stale", "no_data")
STOP_REASONS = ("max_size", "folder_full", "disk_low", "write_error", "requested", "shutdown")


def _number(value) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value) else None


def _feature(rover, cls):
    try:
        return rover.feature(cls)
    except Exception:  # a feature this app was built without
        return None


class RobotCollector:
    def __init__(self, fleet):
        self.fleet = fleet

    def collect(self):
        from rover_web.camera.service import CameraStreams
        from rover_web.estop import EStopService
        from rover_web.geofence import GeofenceService
        from rover_web.recording.service import RecordingService
        from rover_web.teleop.service import TeleopService

        g = {
            "estop": GaugeMetricFamily("rover_web_estop_engaged", "1 while the robot's e-stop is engaged",
                                       labels=("robot",)),
            "estop_since": GaugeMetricFamily("rover_web_estop_engaged_since_seconds",
                                             "Unix time the engaged e-stop was engaged", labels=("robot",)),
            "operator": GaugeMetricFamily("rover_web_operator_present", "1 while someone holds the joystick",
                                          labels=("robot",)),
            "rtt": GaugeMetricFamily("rover_web_link_round_trip_seconds",
                                     "The driving operator's link round trip (teleop pings, lower median)",
                                     labels=("robot",)),
            "link": GaugeMetricFamily("rover_web_robot_link", "The robot link's state: 1 for the current one",
                                      labels=("robot", "state")),
            "percent": GaugeMetricFamily("rover_web_battery_percent", "Battery charge, 0-100", labels=("robot",)),
            "volts": GaugeMetricFamily("rover_web_battery_voltage_volts", "Battery voltage", labels=("robot",)),
            "rate": GaugeMetricFamily("rover_web_topic_rate_hz", "A watched topic's message rate",
                                      labels=("robot", "topic")),
            "age": GaugeMetricFamily("rover_web_topic_age_seconds", "Since a watched topic's last message",
                                     labels=("robot", "topic")),
            "viewers": GaugeMetricFamily("rover_web_viewers", "Open viewers by stream kind",
                                         labels=("robot", "kind")),
            "recording": GaugeMetricFamily("rover_web_recording_active", "1 while a recording runs",
                                           labels=("robot",)),
            "rec_bytes": GaugeMetricFamily("rover_web_recording_bytes", "Bytes written by the running recording",
                                           labels=("robot",)),
        }
        c = {
            "stops": CounterMetricFamily("rover_web_teleop_stops", "Motion stopped by the server, by reason",
                                         labels=("robot", "reason")),
            "rec_stops": CounterMetricFamily("rover_web_recording_stops", "Recordings ended, by reason "
                                             "(max_size, folder_full, disk_low: a limit)", labels=("robot", "reason")),
            "geofence": CounterMetricFamily("rover_web_geofence_refused", "Goals and routes refused for leaving "
                                            "the geofence", labels=("robot",)),
        }
        for rover in self.fleet:
            name = rover.robot.name
            try:
                self._robot(rover, name, g, c, EStopService, TeleopService, CameraStreams, RecordingService,
                            GeofenceService)
            except Exception:  # one robot's odd state must not cost the scrape
                log.exception("metrics: could not read robot %s", name)
        yield from g.values()
        yield from c.values()

    @staticmethod
    def _robot(rover, name, g, c, EStopService, TeleopService, CameraStreams, RecordingService, GeofenceService):
        estop = rover.feature(EStopService).state()
        g["estop"].add_metric((name,), 1.0 if estop.get("engaged") else 0.0)
        if estop.get("engaged") and _number(estop.get("since")) is not None:
            g["estop_since"].add_metric((name,), float(estop["since"]))
        controller = rover.feature(TeleopService).controller
        holder = controller._holder  # a plain attribute, read on every frame (teleop/control.py)
        g["operator"].add_metric((name,), 1.0 if holder is not None else 0.0)
        if holder is not None:
            rtt = _number(holder.link.snapshot().get("rtt_ms"))
            if rtt is not None:
                g["rtt"].add_metric((name,), rtt / 1000.0)
        stats = controller.stats
        c["stops"].add_metric((name, "deadman"), float(stats.get("deadman_stops", 0)))
        c["stops"].add_metric((name, "link"), float(stats.get("link_stops", 0)))
        status = rover.hub.latest("status") or {}
        link = status.get("robot_link", "no_data")
        for state in LINK_STATES:
            g["link"].add_metric((name, state), 1.0 if state == link else 0.0)
        for topic in status.get("topics", ()):
            g["rate"].add_metric((name, topic["topic"]), float(topic.get("rate_hz") or 0.0))
            if _number(topic.get("age_s")) is not None:
                g["age"].add_metric((name, topic["topic"]), float(topic["age_s"]))
        battery = rover.hub.latest("battery") or {}
        if _number(battery.get("percent")) is not None:
            g["percent"].add_metric((name,), float(battery["percent"]))
        if _number(battery.get("voltage")) is not None:
            g["volts"].add_metric((name,), float(battery["voltage"]))
        g["viewers"].add_metric((name, "events"), float(rover.hub.client_count))
        camera = _feature(rover, CameraStreams)
        if camera is not None:
            g["viewers"].add_metric((name, "mjpeg"), float(camera.viewers))
        try:
            from rover_web.camera.webrtc.service import WebRtcService
            webrtc = _feature(rover, WebRtcService)
        except ImportError:  # aiortc missing: no WebRTC on this robot
            webrtc = None
        if webrtc is not None:
            g["viewers"].add_metric((name, "webrtc"), float(len(webrtc.sessions())))
        recording = _feature(rover, RecordingService)
        if recording is not None:
            active = recording._active
            g["recording"].add_metric((name,), 1.0 if active is not None else 0.0)
            g["rec_bytes"].add_metric((name,), float(active.recorder.size) if active is not None else 0.0)
            for reason, count in sorted(recording.stops.items()):
                c["rec_stops"].add_metric((name, reason if reason in STOP_REASONS else "other"), float(count))
        geofence = _feature(rover, GeofenceService)
        if geofence is not None:
            c["geofence"].add_metric((name,), float(geofence.refused))
