"""The 3D view under load: a 100,000-point PointCloud2 at 10 Hz (bench/cloud_publisher.py, another
process) to 5 viewers long-polling GET /api/3d/cloud as the page does.

Prints the server's CPU (its own process: `flask run`) with no viewer and with the viewers, the points
in each frame a viewer got, each frame's age when it was read (the cloud's stamp, the publisher's wall
clock, to the end of the viewer's read: one machine, one clock), and how many frames a viewer got a
second. Then, with --browser, the /3d page in headless Chromium (software GL, SwiftShader) drawing the
thinned cloud and a 30-link model on every animation frame: its frames a second.

    .venv/bin/python bench/view3d.py [--seconds 15] [--viewers 5] [--browser]

The last line is one JSON object with the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import threading
import time

import requests
from common import Server, machine, percentile, ros_env, start_peer, stop_process

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from rover_web.view3d.cloud import decode  # noqa: E402

# Fast DDS moves a message bigger than its shared-memory segment (512 KB by default) over UDP, whose
# default socket buffers lose most 1.6 MB best-effort clouds: a plain rclpy subscriber took 1.25 of 10
# clouds a second here. A larger segment, as docs/view3d.md advises for a robot with a 3D lidar.
FASTDDS_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor><transport_id>shm_big</transport_id><type>SHM</type>
      <segment_size>33554432</segment_size></transport_descriptor>
    <transport_descriptor><transport_id>udp</transport_id><type>UDPv4</type></transport_descriptor>
  </transport_descriptors>
  <participant profile_name="big_shm" is_default_profile="true">
    <rtps><userTransports><transport_id>shm_big</transport_id><transport_id>udp</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports></rtps>
  </participant>
</profiles>
"""


def chain_urdf(links: int) -> str:
    """A robot of `links` boxes on revolute joints, each 0.3 m above the last, turned a little."""
    parts = ['<?xml version="1.0"?>', '<robot name="chain">']
    for i in range(links):
        parts.append(f'<link name="l{i}"><visual><geometry><box size="0.2 0.2 0.25"/></geometry>'
                     f'<material name="m{i}"><color rgba="{i / links:.2f} 0.4 {1 - i / links:.2f} 1"/></material>'
                     '</visual></link>')
        if i:
            parts.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
                         '<origin xyz="0 0 0.3" rpy="0 0 0.2"/><axis xyz="0 0 1"/>'
                         '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)


class Viewer(threading.Thread):
    def __init__(self, url: str, stop: threading.Event):
        super().__init__(daemon=True)
        self.url, self.stop = url, stop
        self.ages: list[float] = []
        self.points: list[int] = []
        self.bytes = 0
        self.measuring = False

    def run(self) -> None:
        session = requests.Session()
        seq = 0
        while not self.stop.is_set():
            try:
                reply = session.get(f"{self.url}/api/3d/cloud", params={"after": seq, "wait": 2}, timeout=10)
            except requests.RequestException:
                if self.stop.is_set():
                    return  # the server stopped under a waiting request
                raise
            read_at = time.time()
            seq = int(reply.headers.get("X-Cloud-Seq", seq))
            if reply.status_code != 200 or not self.measuring:
                continue
            header, xyz, _ = decode(reply.content)
            self.ages.append(read_at - header["stamp"])
            self.points.append(header["count"])
            self.bytes += len(reply.content)


WATCH_PAGE = """async (seconds) => {
    const stage = document.getElementById('view3d');
    stage.dataset.continuous = 'yes';
    const v = stage.view3d;
    const drawn0 = v.drawn;
    let frames = 0;
    const start = performance.now();
    await new Promise((done) => {
        const tick = () => {
            frames += 1;
            if (performance.now() - start < seconds * 1000) requestAnimationFrame(tick); else done();
        };
        requestAnimationFrame(tick);
    });
    const elapsed = (performance.now() - start) / 1000;
    return { fps: frames / elapsed, draws_per_s: (v.drawn - drawn0) / elapsed,
             points: v.layers.cloud.last ? v.layers.cloud.last.header.count : 0, links: v.layers.robot.links.size,
             renderer: v.renderer.getContext().getParameter(v.renderer.getContext().RENDERER) };
}"""


def watch_page(url: str, seconds: float) -> dict:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium",
                                     args=["--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                                           "--enable-unsafe-swiftshader"])
        try:
            page = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True).new_page()
            page.goto(f"{url}/3d")
            page.wait_for_function("() => { const v = document.getElementById('view3d').view3d;"
                                   " return v && v.layers.robot.links.size === 30 && v.layers.cloud.last; }",
                                   timeout=60000)
            return page.evaluate(WATCH_PAGE, seconds)
        finally:
            browser.close()


def run(viewers: int, seconds: float, points: int, browser: bool, big_shm: bool) -> dict:
    tmp = tempfile.TemporaryDirectory(prefix="rover_web-bench-view3d-")
    urdf = os.path.join(tmp.name, "chain.urdf")
    with open(urdf, "w") as f:
        f.write(chain_urdf(30))
    extra = {}
    if big_shm:
        extra["FASTRTPS_DEFAULT_PROFILES_FILE"] = os.path.join(tmp.name, "fastdds.xml")
        with open(extra["FASTRTPS_DEFAULT_PROFILES_FILE"], "w") as f:
            f.write(FASTDDS_PROFILE)
    env = ros_env(ROVER_WEB_POINTCLOUD_TOPIC="/points", ROVER_WEB_URDF_FILE=urdf, **extra)
    server = Server(env)
    pub = None
    stop = threading.Event()
    try:
        pub = start_peer("cloud_publisher.py", env, "--points", str(points), "--seconds",
                         str(2 * seconds + 10 + (40 if browser else 0)))
        requests.get(f"{server.url}/api/3d/cloud", params={"after": 0, "wait": 2}, timeout=10)  # discovery
        time.sleep(1.0)
        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        time.sleep(seconds)
        idle_cpu = 100 * (server.cpu_seconds() - cpu0) / (time.monotonic() - t0)
        fleet = [Viewer(server.url, stop) for _ in range(viewers)]
        for v in fleet:
            v.start()
        time.sleep(1.0)
        for v in fleet:
            v.measuring = True
        received0 = requests.get(f"{server.url}/api/3d/robot", timeout=5).json()["cloud"]["received"]
        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        time.sleep(seconds)
        cpu1, t1 = server.cpu_seconds(), time.monotonic()
        received1 = requests.get(f"{server.url}/api/3d/robot", timeout=5).json()["cloud"]["received"]
        for v in fleet:
            v.measuring = False
        stop.set()
        ages = [a for v in fleet for a in v.ages]
        pts = [p for v in fleet for p in v.points]
        result = {"big_shm": big_shm, "viewers": viewers, "source_points": points, "seconds": round(t1 - t0, 1),
                  "cpu_pct_idle": round(idle_cpu, 1), "cpu_pct": round(100 * (cpu1 - cpu0) / (t1 - t0), 1),
                  "clouds_received_per_s": round((received1 - received0) / (t1 - t0), 2),
                  "frames_per_s_per_viewer": round(len(ages) / viewers / (t1 - t0), 2),
                  "points_per_frame_max": max(pts) if pts else None,
                  "points_per_frame_median": statistics.median(pts) if pts else None,
                  "age_ms_median": round(1000 * statistics.median(ages), 1) if ages else None,
                  "age_ms_p99": round(1000 * percentile(ages, 99), 1) if ages else None,
                  "kb_per_s_per_viewer": round(sum(v.bytes for v in fleet) / viewers / (t1 - t0) / 1e3, 1),
                  "rss_mb": round(server.rss_mb())}
        if browser:
            result["page"] = watch_page(server.url, 10.0)
        return result
    finally:
        stop.set()
        if pub is not None:
            stop_process(pub)
        server.stop()
        tmp.cleanup()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=15.0)
    parser.add_argument("--viewers", type=int, default=5)
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--browser", action="store_true", help="also measure the /3d page in Chromium")
    parser.add_argument("--default-dds", action="store_true",
                        help="Fast DDS's default transports (512 KB shared-memory segments) instead of 32 MB ones")
    args = parser.parse_args()
    print(machine(), f"load average {os.getloadavg()[0]:.1f} at the start (a shared machine)")
    r = run(args.viewers, args.seconds, args.points, args.browser, not args.default_dds)
    print(f"{r['source_points']} points at 10 Hz: server CPU {r['cpu_pct_idle']}% of a core with no viewer, "
          f"{r['cpu_pct']}% with {r['viewers']} viewers; RSS {r['rss_mb']} MB")
    print(f"  the server received {r['clouds_received_per_s']} clouds/s; "
          f"per viewer {r['frames_per_s_per_viewer']} frames/s, {r['kb_per_s_per_viewer']} kB/s; points per frame "
          f"median {r['points_per_frame_median']} max {r['points_per_frame_max']}; frame age median "
          f"{r['age_ms_median']} ms p99 {r['age_ms_p99']} ms")
    if "page" in r:
        p = r["page"]
        print(f"  page: {p['fps']:.1f} frames/s ({p['draws_per_s']:.1f} renders/s) drawing {p['points']} points and "
              f"{p['links']} links on {p['renderer']}")
    print(json.dumps({"bench": "view3d", **r}))


if __name__ == "__main__":
    main()
