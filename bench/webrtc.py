"""WebRTC (WHEP) video on loopback: 1, 2 and 4 aiortc viewers of a 640×480 camera at 30 Hz.

Per viewer count: frames per second each viewer decodes, kbit/s per viewer (RTP payload), the
server's CPU (% of one core, and per viewer), the adaptation level the server chose, and the
glass-to-glass frame age: from the moment the camera process stamped a frame (wall clock, written
into the picture as a 32-bit time code of 16×16 blocks along its top, which survives the VP8
encoder) to the moment the viewer has that frame decoded. rover_web/sim/timecode.py (another
change) draws the simulator's time code; until it is merged this bench's camera draws its own.

    .venv/bin/python bench/webrtc.py [--seconds 10] [--viewers 1 2 4]
    .venv/bin/python bench/webrtc.py --camera   # the camera alone (what the bench starts)
"""

from __future__ import annotations

import argparse
import array
import asyncio
import statistics
import subprocess
import sys
import time

import browser_jitter
import numpy as np
import requests
from common import (
    ROOT,
    Server,
    count_rtp_payload,
    decoded_frames,
    machine,
    percentile,
    ros_env,
    stop_process,
    wait_for,
    wait_for_topic,
)

sys.path.insert(0, str(ROOT))
from tests.support.whep import WhepClient  # noqa: E402

TOPIC = "/bench/camera"
WIDTH, HEIGHT, HZ = 640, 480, 30.0
BLOCK = 16
BITS = 32


def draw_timecode(pixels: np.ndarray, value: int) -> None:
    """value's 32 bits as black/white 16×16 blocks along the top row (most significant first)."""
    for i in range(BITS):
        bit = (value >> (BITS - 1 - i)) & 1
        pixels[0:BLOCK, i * BLOCK:(i + 1) * BLOCK] = 255 if bit else 0


def read_timecode(grey: np.ndarray) -> int | None:
    if grey.shape[0] < BLOCK or grey.shape[1] < BITS * BLOCK:
        return None
    value = 0
    for i in range(BITS):
        centre = grey[4:BLOCK - 4, i * BLOCK + 4:(i + 1) * BLOCK - 4].mean()
        value = (value << 1) | int(centre > 128)
    return value


def camera() -> None:
    """A 640×480 rgb8 camera at 30 Hz: moving bars, grain, and the wall-clock ms (mod 2^32) as a time code."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import Image

    rclpy.init()
    node = rclpy.create_node("bench_webrtc_camera")
    pub = node.create_publisher(Image, TOPIC, 10)
    rng = np.random.default_rng(1)
    grain = rng.integers(0, 24, (8, HEIGHT, WIDTH, 3), dtype=np.uint8)
    x = np.arange(WIDTH, dtype=np.uint16)
    count = [0]

    def tick() -> None:
        n = count[0]
        row = ((x + 4 * n) % 256).astype(np.uint8)
        pixels = np.empty((HEIGHT, WIDTH, 3), np.uint8)
        pixels[:] = row[None, :, None]
        pixels += grain[n % len(grain)]
        now = time.time()
        draw_timecode(pixels, int(now * 1000) & 0xFFFFFFFF)
        msg = Image()
        msg.header.stamp.sec, msg.header.stamp.nanosec = int(now), int((now % 1) * 1e9)
        msg.width, msg.height, msg.encoding, msg.step = WIDTH, HEIGHT, "rgb8", WIDTH * 3
        data = array.array("B")
        data.frombytes(pixels.tobytes())  # an array.array is taken as is; bytes would be checked byte by byte
        msg.data = data
        pub.publish(msg)
        count[0] = n + 1

    node.create_timer(1.0 / HZ, tick)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print("ready", flush=True)
    try:
        executor.spin()
    except KeyboardInterrupt:
        pass


class Viewer:
    """A WhepClient that reads each decoded frame's time code and counts RTP payload bytes."""

    def __init__(self, url: str):
        self.ages: list[float] = []
        self.bytes = 0
        self.decoded = 0
        self.client = WhepClient(url, f"topic={TOPIC}&msg_type=sensor_msgs/msg/Image")
        self.client.loop.run(self._tap(), 10)

    async def _tap(self) -> None:
        receiver = self.client.pc.getTransceivers()[0].receiver
        count_rtp_payload(receiver, self._count)
        # Frames to the decoder at their marker bit, as a browser hands them over: aiortc's own
        # jitter buffer waits for the next frame's first packet, one frame interval more.
        browser_jitter.install(receiver)
        # Replace the test client's reader: this one decodes to grey and reads the time code.
        if self.client._reader is not None:
            self.client._reader.cancel()
        asyncio.ensure_future(self._read(receiver.track))

    def _count(self, n: int) -> None:
        self.bytes += n

    async def _read(self, track) -> None:
        async for frame in decoded_frames(track):
            now_ms = int(time.time() * 1000) & 0xFFFFFFFF
            stamp = read_timecode(frame.to_ndarray(format="gray"))
            self.decoded += 1
            if stamp is not None:
                age = ((now_ms - stamp) & 0xFFFFFFFF) / 1000
                if age < 10:  # a misread code is nonsense, not a 40-day-old frame
                    self.ages.append(age)

    def close(self) -> None:
        self.client.close()


def run(server: Server, viewers: int, seconds: float) -> dict:
    clients = []
    try:
        for _ in range(viewers):
            clients.append(Viewer(server.url))
        for v in clients:
            wait_for(lambda v=v: v.decoded >= 30, 30, "first frames")
        time.sleep(3.0)  # past the adaptation's first steps
        for v in clients:
            v.ages.clear()
        decoded0, bytes0 = [v.decoded for v in clients], [v.bytes for v in clients]
        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        time.sleep(seconds)
        cpu1, t1 = server.cpu_seconds(), time.monotonic()
        dt = t1 - t0
        fps = [(v.decoded - d) / dt for v, d in zip(clients, decoded0, strict=True)]
        kbps = [8 * (v.bytes - b) / dt / 1000 for v, b in zip(clients, bytes0, strict=True)]
        ages = [a for v in clients for a in v.ages]
        sessions = requests.get(server.url + "/api/camera/whep", timeout=5).json()["sessions"]
    finally:
        for v in clients:
            v.close()
    cpu = 100 * (cpu1 - cpu0) / dt
    return {"viewers": viewers, "fps_median": statistics.median(fps), "fps_min": min(fps),
            "kbps_median": statistics.median(kbps), "cpu_pct": cpu, "cpu_per_viewer": cpu / viewers,
            "age_ms": (1000 * statistics.median(ages), 1000 * percentile(ages, 99)) if ages else None,
            "source_hz": statistics.median([s["source_hz"] or 0 for s in sessions]),
            "levels": sorted({s["level"] for s in sessions if s["level"] is not None}),
            "sizes": sorted({f"{s['width']}x{s['height']}@{s['fps']:g}" for s in sessions if s["width"]}),
            "rss_mb": server.rss_mb()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--viewers", type=int, nargs="*", default=[1, 2, 4])
    parser.add_argument("--camera", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.camera:
        camera()
        return
    env = ros_env(ROVER_WEB_WEBRTC_MAX_VIEWERS="8", ROVER_WEB_WEBRTC_HOST_ADDRESSES="127.0.0.1",
                  ROVER_WEB_CAMERA_IDLE_TIMEOUT_S="30")
    camera_proc = subprocess.Popen([sys.executable, __file__, "--camera"], cwd=ROOT, env=env,
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    server = None
    try:
        assert camera_proc.stdout.readline().strip() == "ready"
        server = Server(env)
        wait_for_topic(server, TOPIC, "camera discovery")
        print(f"# WebRTC bench on {machine()}: {WIDTH}x{HEIGHT} rgb8 {HZ:g} Hz camera (own process) -> WHEP, "
              f"aiortc viewers in the bench process, loopback, {args.seconds:g} s per run", flush=True)
        for n in args.viewers:
            r = run(server, n, args.seconds)
            age = r["age_ms"]
            print(f"viewers {n}: fps/viewer median {r['fps_median']:5.1f} min {r['fps_min']:5.1f}  "
                  f"kbit/s/viewer {r['kbps_median']:6.0f}  server CPU {r['cpu_pct']:5.1f}% of one core "
                  f"({r['cpu_per_viewer']:4.1f}% per viewer)  glass-to-glass "
                  + (f"median {age[0]:5.1f} ms p99 {age[1]:5.1f} ms" if age else "n/a")
                  + f"  camera arrivals {r['source_hz']:.1f}/s  level {r['levels']} {r['sizes']}"
                  f"  RSS {r['rss_mb']:.0f} MB", flush=True)
    finally:
        if server is not None:
            server.stop()
        stop_process(camera_proc)


if __name__ == "__main__":
    main()
