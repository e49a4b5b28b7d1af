"""LiveMap overlays under load: a 1,080-beam LaserScan at 20 Hz and a 400 x 400 costmap at 1 Hz
(bench/overlay_publisher.py, another process) to N SSE viewers of `scan` and `costmap`.

Prints the server's CPU (its own process: `flask run`), the age of each event when it reached a
viewer (publisher's CLOCK_MONOTONIC stamp -> the frame's arrival in the viewer's socket), how many
scan and costmap events each viewer got a second, and their sizes on the wire, once with the
overlays and once with no scan or costmap subscribed (the baseline the overlays add to).

    .venv/bin/python bench/overlays.py [--seconds 10] [--clients 10] [--browser] [--tf]

--tf has the publisher send TF and the scan placed through it (one lookup a scan) instead of
AMCL's pose and the configured laser offset.

--browser also opens the LiveMap page in Chromium (Playwright, /usr/bin/chromium) during the run
with the overlays on, and prints the page's frames a second (requestAnimationFrame callbacks),
its draws a second, and its long tasks (over 50 ms, PerformanceObserver): what "10+ fps without
stalling the page" means, measured.
"""

from __future__ import annotations

import argparse
import statistics
import time

from common import Server, SseFleet, machine, percentile, ros_env, start_peer, stop_process

WATCH_PAGE = """async (seconds) => {
    const longTasks = [];
    new PerformanceObserver((list) => { for (const e of list.getEntries()) longTasks.push(e.duration); })
        .observe({ type: 'longtask', buffered: false });
    const draws0 = window.liveMapState.drawCount;
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
    return { fps: frames / elapsed, draws: (window.liveMapState.drawCount - draws0) / elapsed,
             longTasks, layers: window.liveMapState.layers };
}"""


def watch_page(url: str, seconds: float) -> dict:
    from urllib.parse import quote

    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium",
                                     args=["--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader"])
        try:
            page = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True).new_page()
            page.goto(f"{url}/livemap/{quote('Science Hall Basement')}")
            page.wait_for_function("window.liveMapState && window.liveMapState.layers"
                                   " && window.liveMapState.layers.scan && window.liveMapState.layers.costmaps.length",
                                   timeout=30000)
            return page.evaluate(WATCH_PAGE, seconds)
        finally:
            browser.close()


def run(clients: int, seconds: float, overlays: bool, browser: bool = False, tf: bool = False) -> dict:
    settings = {} if overlays else {"ROVER_WEB_SCAN_TOPIC": "", "ROVER_WEB_COSTMAP_TOPICS": ""}
    env = ros_env(**settings)
    server = Server(env)
    fleet = SseFleet(server.url, "/api/events?channels=scan,costmap", clients)
    pub = None
    try:
        fleet.poll(0.5, lambda *a: None)  # the snapshots
        # With the page to watch after the viewers' run, the publisher goes on for it too.
        pub = start_peer("overlay_publisher.py", env, "--seconds", str(seconds + (25 if browser else 2)),
                         *(["--tf"] if tf else []))
        fleet.poll(1.0, lambda *a: None)  # discovery and the first grid, not measured
        ages = {"scan": [], "costmap": []}
        sizes = {"scan": [], "costmap": []}
        placed: dict[str, int] = {}

        def on_event(t_woken, t_arrived, name, data):
            if name == "scan" and data.get("stamp"):
                ages["scan"].append(t_arrived - data["stamp"])
                sizes["scan"].append(len(data["points"]) // 2)
                how = data.get("placed_by", "configured")  # the scan before TF had no placed_by
                placed[how] = placed.get(how, 0) + 1
            elif name == "costmap":
                for layer in data["costmaps"]:
                    ages["costmap"].append(t_arrived - layer["stamp"])
                    sizes["costmap"].append(len(layer["data"]))

        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        fleet.poll(seconds, on_event)
        cpu1, t1 = server.cpu_seconds(), time.monotonic()
        page = watch_page(server.url, min(seconds, 5.0)) if browser else None
        return {"page": page, "clients": clients, "overlays": overlays, "tf": tf,
                "cpu_pct": 100 * (cpu1 - cpu0) / (t1 - t0),
                "seconds": t1 - t0, "ages": ages, "sizes": sizes, "placed": placed, "bytes": fleet.bytes_received,
                "rss_mb": server.rss_mb()}
    finally:
        if pub is not None:
            stop_process(pub)
        fleet.close()
        server.stop()


def report(r: dict) -> None:
    label = ("overlays on " + ("(TF)" if r.get("tf") else "")) if r["overlays"] else "overlays off"
    print(f"{label}: {r['clients']} viewers, server CPU {r['cpu_pct']:.1f}% of a core, RSS {r['rss_mb']:.0f} MB, "
          f"{r['bytes'] / r['seconds'] / 1e3 / r['clients']:.1f} kB/s per viewer"
          + (f"; scans placed by {r['placed']}" if r.get("placed") else ""))
    for name in ("scan", "costmap"):
        ages = [a * 1000 for a in r["ages"][name]]
        if not ages:
            continue
        per_viewer_hz = len(ages) / r["clients"] / r["seconds"]
        print(f"  {name:8s} {per_viewer_hz:5.1f} events/s per viewer, age median {statistics.median(ages):6.1f} ms "
              f"p99 {percentile(ages, 99):6.1f} ms max {max(ages):6.1f} ms; "
              f"{'points' if name == 'scan' else 'base64 bytes'} per event {statistics.median(r['sizes'][name]):.0f}")
    if r.get("page"):
        p = r["page"]
        long_tasks = p["longTasks"]
        print(f"  page: {p['fps']:.1f} frames/s, {p['draws']:.1f} draws/s, {len(long_tasks)} long tasks"
              f"{f' (longest {max(long_tasks):.0f} ms)' if long_tasks else ''}; layers {p['layers']['scan']}, "
              f"{len(p['layers']['costmaps'])} costmap(s)")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--clients", type=int, default=10)
    parser.add_argument("--browser", action="store_true", help="also measure the page in Chromium")
    parser.add_argument("--tf", action="store_true", help="place the scan through TF (the publisher sends it)")
    args = parser.parse_args()
    print(machine())
    for overlays in (False, True):
        result = run(args.clients, args.seconds, overlays, browser=args.browser and overlays, tf=args.tf)
        report(result)


if __name__ == "__main__":
    main()
