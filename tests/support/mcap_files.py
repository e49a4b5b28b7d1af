"""MCAP files made in tests, as rover_web's recorder writes them (ros2msg schemas, CDR from rclpy),
with known content at known times, so the replay view's answers can be checked exactly.

`write_run(path)` writes RUN_S seconds starting at T0 (seconds since the epoch):
- /amcl_pose (PoseWithCovarianceStamped, 10 Hz): x = 1 + 0.5 s, y = 2, yaw = 0.5 (in the map frame)
- /odom (Odometry, 20 Hz): pose.pose.position.x = s, twist.twist.linear.x = 1, twist.twist.angular.z = NaN at s = 4
- /fix (NavSatFix, 5 Hz): 27.37 + 1e-5 s, -82.45
- /diagnostics (DiagnosticArray, 1 Hz): "motor" (hardware "drive") OK until s = 5, then ERROR "overheat",
  temp = 40 + s; "battery" (hardware "power") WARN "low"; "gps" (hardware "gnss") OK once, at s = 2 only
- /camera/image_raw (Image rgb8 64x48, 2 Hz): frame i at s = i / 2, all red for even i, all blue for odd i
- /rosout (Log): "thruster two hot" (WARN) at s = 3
- /rover_web/audit (String, JSON): estop.engage by carol at s = 6
where s is the time since T0.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

T0 = 1_764_000_000.0
RUN_S = 10.0
RED, BLUE = (255, 0, 0), (0, 0, 255)
WIDTH, HEIGHT = 64, 48


def _ns(s: float) -> int:
    return int(round((T0 + s) * 1e9))


def pose_x(s: float) -> float:
    return 1.0 + 0.5 * s


def frame_colour(i: int) -> tuple[int, int, int]:
    return RED if i % 2 == 0 else BLUE


def messages(seconds: float = RUN_S) -> list[tuple[str, str, float, object]]:
    """(topic, type, s, message) of the run, in time order."""
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from nav_msgs.msg import Odometry
    from rcl_interfaces.msg import Log
    from sensor_msgs.msg import Image, NavSatFix
    from std_msgs.msg import String

    out: list[tuple[str, str, float, object]] = []

    def every(period: float):
        return [round(i * period, 6) for i in range(int(seconds / period + 1e-9))]

    for s in every(0.1):
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = "map"
        msg.pose.pose.position.x, msg.pose.pose.position.y = pose_x(s), 2.0
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(0.25), math.cos(0.25)  # yaw 0.5
        out.append(("/amcl_pose", "geometry_msgs/msg/PoseWithCovarianceStamped", s, msg))
    for s in every(0.05):
        msg = Odometry()
        msg.header.frame_id = "odom"
        msg.pose.pose.position.x = s
        msg.pose.pose.orientation.w = 1.0
        msg.twist.twist.linear.x = 1.0
        msg.twist.twist.angular.z = math.nan if s == 4.0 else 0.1
        out.append(("/odom", "nav_msgs/msg/Odometry", s, msg))
    for s in every(0.2):
        fix = NavSatFix(latitude=27.37 + 1e-5 * s, longitude=-82.45)
        fix.status.status = 0  # a fix (Jazzy's default is STATUS_UNKNOWN, which the GPS map leaves out)
        out.append(("/fix", "sensor_msgs/msg/NavSatFix", s, fix))
    for s in every(1.0):
        motor = DiagnosticStatus(name="motor", hardware_id="drive", level=DiagnosticStatus.OK if s < 5 else
                                 DiagnosticStatus.ERROR, message="ok" if s < 5 else "overheat",
                                 values=[KeyValue(key="temp", value=f"{40 + s:g}")])
        battery = DiagnosticStatus(name="battery", hardware_id="power", level=DiagnosticStatus.WARN, message="low")
        statuses = [motor, battery]
        if s == 2.0:
            statuses.append(DiagnosticStatus(name="gps", hardware_id="gnss", level=DiagnosticStatus.OK, message="fix"))
        out.append(("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", s, DiagnosticArray(status=statuses)))
    for i, s in enumerate(every(0.5)):
        colour = bytes(frame_colour(i))
        out.append(("/camera/image_raw", "sensor_msgs/msg/Image", s,
                    Image(width=WIDTH, height=HEIGHT, encoding="rgb8", step=WIDTH * 3, data=colour * (WIDTH * HEIGHT))))
    out.append(("/rosout", "rcl_interfaces/msg/Log", 3.0, Log(level=30, name="replay_peer", msg="thruster two hot")))
    record = {"timestamp": {"sec": int(T0 + 6), "nsec": 0}, "action": "estop.engage", "by": "carol",
              "detail": "e-stop engaged by carol", "robot": "robot", "metadata": {}}
    out.append(("/rover_web/audit", "std_msgs/msg/String", 6.0, String(data=json.dumps(record))))
    out.sort(key=lambda item: item[2])
    return out


def write_run(path: Path, seconds: float = RUN_S, compression: str = "lz4") -> Path:
    """The run as an MCAP file, chunked and compressed as the recorder writes it."""
    from mcap.writer import CompressionType, Writer
    from rclpy.serialization import serialize_message

    from rover_web.recording.schema import schema_text

    items = messages(seconds)
    with open(path, "wb") as f:
        writer = Writer(f, chunk_size=64 * 1024,
                        compression=CompressionType.LZ4 if compression == "lz4" else CompressionType.ZSTD)
        writer.start(profile="ros2", library="rover_web tests")
        schemas: dict[str, int] = {}
        channels: dict[str, int] = {}
        for topic, type_name, _s, _msg in items:
            if type_name not in schemas:
                schemas[type_name] = writer.register_schema(type_name, "ros2msg", schema_text(type_name).encode())
            if topic not in channels:
                channels[topic] = writer.register_channel(topic, "cdr", schemas[type_name])
        for sequence, (topic, _type, s, msg) in enumerate(items):
            writer.add_message(channels[topic], log_time=_ns(s), data=serialize_message(msg), publish_time=_ns(s),
                               sequence=sequence)
        writer.finish()
    return path


def upload(server, path: Path, name: str = "from elsewhere", headers=None):
    import requests

    with open(path, "rb") as body:
        return requests.post(f"{server.url}/api/recordings/upload", params={"name": name}, data=body,
                             headers={"Content-Type": "application/octet-stream", **(headers or {})}, timeout=30)
