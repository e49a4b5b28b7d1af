"""Recording cost: 20 topics, /odom at 50 Hz and a 640x480 camera at 10 fps, recorded for ~20 s.

The app runs in its own process (its CPU is its own); a second process publishes the topics:
/odom (nav_msgs/Odometry, 50 Hz), /camera/image_raw (sensor_msgs/Image rgb8 640x480, 10 Hz; a moving
gradient with noise, so zstd gets a camera-like ratio, not a blank frame's), /imu (sensor_msgs/Imu,
50 Hz), /fix (5 Hz), /battery_state (1 Hz) and 15 /bench/sensor_N (std_msgs/Float64MultiArray of
16 values, 10 Hz). Phases: the same traffic not recorded (baseline), then recorded with the camera
(ROVER_WEB_RECORDING_CAMERA_MAX_HZ=10). Prints the recorder's CPU (recording minus baseline, % of
one core), MB per minute, messages written and dropped against those published, and the latency
of the `odom` event (the /odom stamp to an SSE client's socket) in both phases.

    .venv/bin/python bench/recording.py [--seconds 20] [--baseline 10]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import requests
from common import ROOT, Server, SseFleet, machine, ros_env, stop_process, summary_ms, wait_for_topic

SENSORS = 15
RATES = {"/odom": 50.0, "/camera/image_raw": 10.0, "/imu": 50.0, "/fix": 5.0, "/battery_state": 1.0,
         **{f"/bench/sensor_{i}": 10.0 for i in range(SENSORS)}}


def publish() -> None:
    """The publisher process: every topic of RATES at its rate, until stdin closes."""
    import threading

    import numpy as np
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.context import Context
    from rclpy.signals import SignalHandlerOptions
    from sensor_msgs.msg import BatteryState, Image, Imu, NavSatFix
    from std_msgs.msg import Float64MultiArray

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_recording_publisher", context=context)
    rng = np.random.default_rng(1)
    gradient = np.tile(np.arange(640, dtype=np.uint16), (480, 1))

    def image(i: int) -> Image:
        frame = np.stack([(gradient + 3 * i) % 256, (gradient.T[:480, :1] + i) % 256 + 0 * gradient,
                          gradient // 3], axis=-1).astype(np.uint8)
        frame ^= rng.integers(0, 8, frame.shape, dtype=np.uint8)  # sensor noise in the low bits
        return Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=frame.tobytes())

    def odom(i: int) -> Odometry:
        msg = Odometry(child_frame_id="base_link")
        ns = time.monotonic_ns()  # CLOCK_MONOTONIC, for the odom event's latency to the SSE client
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000
        return msg

    makers = {"/odom": (Odometry, odom),
              "/camera/image_raw": (Image, image), "/imu": (Imu, lambda i: Imu()),
              "/fix": (NavSatFix, lambda i: NavSatFix(latitude=27.37, longitude=-82.45)),
              "/battery_state": (BatteryState, lambda i: BatteryState(voltage=12.0)),
              **{f"/bench/sensor_{k}": (Float64MultiArray,
                                        lambda i: Float64MultiArray(data=[float(i)] * 16)) for k in range(SENSORS)}}
    publishers = {topic: node.create_publisher(cls, topic, 10) for topic, (cls, _) in makers.items()}
    stop = threading.Event()

    def run(topic: str) -> None:
        period, make, pub = 1.0 / RATES[topic], makers[topic][1], publishers[topic]
        start, i = time.monotonic(), 0
        while not stop.is_set():
            pub.publish(make(i))
            i += 1
            stop.wait(max(0.0, start + i * period - time.monotonic()))

    threads = [threading.Thread(target=run, args=(t,), daemon=True) for t in makers]
    for thread in threads:
        thread.start()
    print("publishing", flush=True)
    sys.stdin.read()
    stop.set()
    for thread in threads:
        thread.join(2)
    node.destroy_node()
    context.try_shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--baseline", type=float, default=10.0)
    parser.add_argument("--no-camera", action="store_true",
                        help="record the other 19 topics only (what the camera costs)")
    args = parser.parse_args()
    folder = tempfile.TemporaryDirectory(prefix="rover_web-bench-rec-")
    env = ros_env(ROVER_WEB_RECORDINGS_DIR=folder.name, ROVER_WEB_RECORDING_CAMERA_MAX_HZ="10",
                  ROVER_WEB_RECORDINGS_MIN_FREE_MB="100")
    server = Server(env)
    publisher = subprocess.Popen([sys.executable, __file__, "--publish"], cwd=ROOT, env=env, stdin=subprocess.PIPE,
                                 stdout=subprocess.PIPE, text=True)
    try:
        if "publishing" not in publisher.stdout.readline():
            raise RuntimeError("the publisher did not start")
        for topic in RATES:
            wait_for_topic(server, topic, f"{topic} discovered")
        fleet = SseFleet(server.url, "/api/events?channels=odom", 1)
        fleet.poll(1.0, lambda *a: None)  # the snapshot
        latency: dict[str, list[float]] = {"not recording": [], "recording": []}

        def measure(phase: str, seconds: float) -> float:
            def on_event(_woken, arrived, name, data):
                if name == "odom" and data.get("stamp"):
                    latency[phase].append(arrived - data["stamp"])
            cpu0, t0 = server.cpu_seconds(), time.monotonic()
            fleet.poll(seconds, on_event)
            return 100 * (server.cpu_seconds() - cpu0) / (time.monotonic() - t0)

        baseline = measure("not recording", args.baseline)

        body = {"topics": list(RATES), "camera": not args.no_camera}
        started = requests.post(server.url + "/api/recordings", json=body, timeout=10).json()
        recording = measure("recording", args.seconds)
        fleet.close()
        done = requests.post(f"{server.url}/api/recordings/{started['id']}/stop", json={}, timeout=30).json()
    finally:
        publisher.stdin.close()
        stop_process(publisher)
        server.stop()
    size_mb = Path(folder.name, f"{started['id']}.mcap").stat().st_size / 1e6
    minutes = done["duration_s"] / 60
    expected = {t: RATES[t] * done["duration_s"] for t in RATES}
    folder.cleanup()
    print(f"machine: {machine()}")
    print(f"recorded {len(done['counts']) - 1} topics for {done['duration_s']:.1f} s: {done['messages']} messages, "
          f"{sum(done['dropped'].values())} dropped")
    for topic in ("/odom", "/camera/image_raw", "/imu", "/bench/sensor_0"):
        print(f"  {topic}: {done['counts'].get(topic, 0)} written of ~{expected[topic]:.0f} published")
    print(f"server CPU: {baseline:.1f} % of a core not recording, {recording:.1f} % recording: "
          f"the recorder {recording - baseline:.1f} %")
    print(f"file: {size_mb:.1f} MB, {size_mb / minutes:.1f} MB per minute")
    for phase, values in latency.items():
        print(f"odom event latency, {phase}: {summary_ms(values)}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--publish"]:  # the publisher process main() starts
        publish()
    else:
        main()
