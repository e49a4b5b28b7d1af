"""The load of N robots from one rclpy process: per robot /<name>/odom (nav_msgs/Odometry) at
50 Hz, /<name>/fix (sensor_msgs/NavSatFix) at 5 Hz and /<name>/battery_state
(sensor_msgs/BatteryState) at 1 Hz, each robot driving a slow circle.

    python bench/fleet_load.py --robots r1,r2,r3 --seconds 60

Every header is stamped with the wall clock (time.time) just before its publish, for latency.
Robots are spread evenly over each period (not all published in one burst), as independent
robots would be. Prints "publishing" once every robot's odometry has a subscriber, and at the end
one JSON line: messages sent per topic kind, how far the loop fell behind its schedule (a
load generator that cannot keep up would make the server look better than it is), and every
change of each robot's /<name>/e_stop (std_msgs/Bool) with the wall-clock time it arrived here,
so the bench can time a "stop all" to the last robot in ROS, not only to the browsers.
"""

from __future__ import annotations

import argparse
import heapq
import json
import math
import signal
import sys
import threading
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import BatteryState, NavSatFix
from std_msgs.msg import Bool

# Where the simulated robots drive (the simulator's origin, Sarasota Bay), and how.
LAT0, LON0 = 27.3742443, -82.4500873
RADIUS_M, SPEED_MPS = 20.0, 1.0
M_PER_DEG_LAT = 111_320.0


def stamp(msg, t_ns: int) -> None:
    msg.header.stamp.sec, msg.header.stamp.nanosec = t_ns // 1_000_000_000, t_ns % 1_000_000_000


LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)


class Robot:
    def __init__(self, node, index: int, name: str, estop_log: list):
        self.name = name
        self.estop: bool | None = None
        self._estop_log = estop_log
        node.create_subscription(Bool, f"/{name}/e_stop", self._on_estop, LATCHED)
        self.phase = index * 0.7  # robots are not on top of each other
        self.odom = node.create_publisher(Odometry, f"/{name}/odom", 10)
        self.fix = node.create_publisher(NavSatFix, f"/{name}/fix", qos_profile_sensor_data)
        self.battery = node.create_publisher(BatteryState, f"/{name}/battery_state", qos_profile_sensor_data)
        self.started = time.monotonic()

    def _on_estop(self, msg) -> None:
        if msg.data != self.estop:  # the flag is republished every few seconds; only changes count
            self.estop = msg.data
            self._estop_log.append((self.name, msg.data, time.time()))

    def _angle(self) -> float:
        return self.phase + SPEED_MPS / RADIUS_M * (time.monotonic() - self.started)

    def send_odom(self) -> None:
        a = self._angle()
        msg = Odometry()
        msg.header.frame_id = "odom"
        msg.child_frame_id = "base_link"
        msg.pose.pose.position.x = RADIUS_M * math.cos(a)
        msg.pose.pose.position.y = RADIUS_M * math.sin(a)
        yaw = a + math.pi / 2
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        msg.twist.twist.linear.x = SPEED_MPS
        msg.twist.twist.angular.z = SPEED_MPS / RADIUS_M
        stamp(msg, time.time_ns())
        self.odom.publish(msg)

    def send_fix(self) -> None:
        a = self._angle()
        msg = NavSatFix()
        msg.header.frame_id = "gps"
        msg.status.status = 0
        msg.status.service = 1
        msg.latitude = LAT0 + RADIUS_M * math.sin(a) / M_PER_DEG_LAT
        msg.longitude = LON0 + RADIUS_M * math.cos(a) / (M_PER_DEG_LAT * math.cos(math.radians(LAT0)))
        msg.altitude = 1.0
        msg.position_covariance = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 4.0]
        msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
        stamp(msg, time.time_ns())
        self.fix.publish(msg)

    def send_battery(self) -> None:
        msg = BatteryState()
        msg.voltage = 24.6
        msg.percentage = 0.8
        msg.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
        msg.present = True
        stamp(msg, time.time_ns())
        self.battery.publish(msg)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", required=True, help="names, comma-separated; topics go under /<name>/")
    parser.add_argument("--seconds", type=float, default=60.0, help="how long to publish (SIGTERM ends it sooner)")
    parser.add_argument("--odom-hz", type=float, default=50.0)
    parser.add_argument("--fix-hz", type=float, default=5.0)
    parser.add_argument("--battery-hz", type=float, default=1.0)
    args = parser.parse_args()
    names = [n.strip() for n in args.robots.split(",") if n.strip()]
    stopping = []
    signal.signal(signal.SIGTERM, lambda *_: stopping.append(True))

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_fleet_load", context=context)
    estop_log: list = []
    robots = [Robot(node, i, name, estop_log) for i, name in enumerate(names)]
    executor = SingleThreadedExecutor(context=context)  # only the e-stop subscriptions; publishing stays here
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    deadline = time.monotonic() + 30
    while any(r.odom.get_subscription_count() == 0 for r in robots) and time.monotonic() < deadline:
        time.sleep(0.05)
    missing = [r.name for r in robots if r.odom.get_subscription_count() == 0]
    if missing:
        print(f"no subscriber on the odometry of {', '.join(missing)}", flush=True)
        sys.exit(1)
    time.sleep(0.5)  # the fix and battery subscriptions are discovered at the same time, give them a moment
    print("publishing", flush=True)

    kinds = (("odom", args.odom_hz), ("fix", args.fix_hz), ("battery", args.battery_hz))
    start = time.monotonic()
    # (due, kind, robot index, period): one heap for every robot and topic, each robot's phase
    # spread over the period so N robots do not publish in one burst.
    queue = [(start + (i / len(robots)) / hz, kind, i, 1.0 / hz)
             for kind, hz in kinds if hz > 0 for i in range(len(robots))]
    heapq.heapify(queue)
    sent = {kind: 0 for kind, _ in kinds}
    late = []
    end = start + args.seconds
    while not stopping:
        due, kind, i, period = queue[0]
        if due >= end:
            break
        if (wait := due - time.monotonic()) > 0:
            time.sleep(wait)
            continue
        late.append(time.monotonic() - due)
        getattr(robots[i], f"send_{kind}")()
        sent[kind] += 1
        heapq.heapreplace(queue, (due + period, kind, i, period))
    elapsed = time.monotonic() - start
    late.sort()
    print(json.dumps({"sent": sent, "seconds": round(elapsed, 2),
                      "rates": {k: round(v / elapsed / max(1, len(robots)), 2) for k, v in sent.items()},
                      "late_p99_ms": round(1000 * late[int(0.99 * (len(late) - 1))], 2) if late else None,
                      "late_max_ms": round(1000 * late[-1], 2) if late else None,
                      "estop": estop_log}), flush=True)
    executor.shutdown(timeout_sec=1)
    node.destroy_node()
    context.try_shutdown()


if __name__ == "__main__":
    main()
