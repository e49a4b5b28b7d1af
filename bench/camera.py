"""MJPEG streaming of the simulated camera (640×480 rgb8, 30 Hz, another process) to 1, 5 and 20 viewers.

Per viewer count: frames per second each viewer receives, server CPU (% of one core), JPEG encode
time per frame, encodes per second (one per frame, whatever the number of viewers), and the
latency from the image's header stamp to its arrival at the viewer.

    .venv/bin/python bench/camera.py [--seconds 10] [--viewers 1 5 20] [--quality 80]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

import psutil
import requests
from common import ROOT, Server, machine, percentile, ros_env, stop_process, wait_for, wait_for_topic

sys.path.insert(0, str(ROOT))
from tests.support.mjpeg import MjpegClient  # noqa: E402

TOPIC = "/camera/image_raw"


def stream_stats(server: Server) -> dict:
    streams = requests.get(server.url + "/api/camera/streams", timeout=5).json()["streams"]
    return streams[0] if streams else {}


def run(server: Server, camera: psutil.Process, viewers: int, seconds: float, quality: int) -> dict:
    url = f"{server.url}/stream?topic={TOPIC}&quality={quality}"
    clients = [MjpegClient(url, keep_frames=False) for _ in range(viewers)]
    try:
        for client in clients:
            wait_for(lambda client=client: client.count >= 10, 20, "first frames")
        time.sleep(1.0)  # settle
        counts0 = [c.count for c in clients]
        for c in clients:
            c.latencies.clear()
        before = stream_stats(server)
        cpu0, cam0, t0 = server.cpu_seconds(), sum(camera.cpu_times()[:2]), time.monotonic()
        time.sleep(seconds)
        cpu1, cam1, t1 = server.cpu_seconds(), sum(camera.cpu_times()[:2]), time.monotonic()
        after = stream_stats(server)
        counts1 = [c.count for c in clients]
        latencies = [x for c in clients for x in c.latencies]
        bytes_per_frame = sum(c.bytes for c in clients) / max(1, sum(c.count for c in clients))
    finally:
        for client in clients:
            client.close()
    fps = [(b - a) / (t1 - t0) for a, b in zip(counts0, counts1, strict=True)]
    dt = t1 - t0
    return {
        "viewers": viewers,
        "fps_median": statistics.median(fps), "fps_min": min(fps),
        "cpu_pct": 100 * (cpu1 - cpu0) / dt,
        "camera_cpu_pct": 100 * (cam1 - cam0) / dt,
        "received_hz": (after["received"] - before["received"]) / dt,
        "encodes_hz": (after["encodes"] - before["encodes"]) / dt,
        "encode_ms": after["encode_ms"],
        "latency_ms": (1000 * statistics.median(latencies), 1000 * percentile(latencies, 99)) if latencies else None,
        "jpeg_kb": bytes_per_frame / 1000,
        "rss_mb": server.rss_mb(),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--viewers", type=int, nargs="*", default=[1, 5, 20])
    parser.add_argument("--quality", type=int, default=80)
    parser.add_argument("--noise", type=float, nargs="*", default=[0.0, 12.0],
                        help="camera grain to run with (0: the clean test pattern; 12: about a real camera's)")
    args = parser.parse_args()
    for noise in args.noise:
        bench(args, noise)


def bench(args, noise: float) -> None:
    env = ros_env(ROVER_WEB_CAMERA_MAX_VIEWERS="64", ROVER_WEB_CAMERA_IDLE_TIMEOUT_S="30")
    camera_proc = subprocess.Popen([sys.executable, "-m", "rover_web.sim.camera", "--camera-noise", str(noise)],
                                   cwd=ROOT, env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    server = None
    try:
        server = Server(env)
        wait_for_topic(server, TOPIC, "camera discovery")
        print(f"# camera bench on {machine()}: sim camera 640x480 rgb8 30 Hz, grain {noise:g} (own process) -> "
              f"/stream quality {args.quality}, {args.seconds:g} s per run", flush=True)
        for n in args.viewers:
            r = run(server, psutil.Process(camera_proc.pid), n, args.seconds, args.quality)
            enc = r["encode_ms"] or {}
            latency = r["latency_ms"]
            print(f"viewers {n:3d}: fps/viewer median {r['fps_median']:5.1f} min {r['fps_min']:5.1f}  "
                  f"server CPU {r['cpu_pct']:5.1f}% of one core  "
                  f"encode median {enc.get('median', float('nan')):5.2f} ms "
                  f"p99 {enc.get('p99', float('nan')):5.2f} ms  "
                  f"encodes {r['encodes_hz']:4.1f}/s of {r['received_hz']:4.1f} frames/s received  "
                  f"latency median {latency[0]:5.1f} ms p99 {latency[1]:5.1f} ms  "
                  f"JPEG {r['jpeg_kb']:.1f} kB  RSS {r['rss_mb']:.0f} MB  camera CPU {r['camera_cpu_pct']:.1f}%",
                  flush=True)
    finally:
        if server is not None:
            server.stop()
        stop_process(camera_proc)


if __name__ == "__main__":
    main()
