"""Opening the GUI over an emulated field link: Chromium through the link emulator, cold and warm.

    .venv/bin/python bench/page_load.py --profile radio|wifi-edge|starlink|wifi-good|loopback
                                        [--pages dashboard,waypoints,livemap,robots,plot,recordings]
                                        [--tree /work/main] [--timeout 60] [--seed 1] [--no-preload]
                                        [--list-requests] [--timeline]

Starts the demo's simulator (`python -m rover_web.sim`) and the app (`flask run`, from --tree: this
checkout by default; another checkout, such as main, to measure before a change: started with no
bytecode written and its state in a scratch folder) in their own processes, and a LinkEmulator
(rover_web/linkemu) in this one in front of the app. Chromium reaches the app through the emulator
only. For each page: a fresh browser context (an empty cache: cold), then a reload in it (warm).

Per load, from the navigation's start (the page's own clock, performance.now()):
- bytes: what the page's finished responses took on the wire (Chromium's encodedDataLength: headers
  and body as sent, compressed or not), open streams (SSE) left out; wire_bytes: every byte the
  emulator passed down to the browser while the load was measured, streams included.
- requests: requests that went to the network (served from the browser's cache: not counted).
- ttfb_ms: the document's first byte (Navigation Timing responseStart).
- estop_ms: the header's E-STOP works: either it is a plain form posting (it works once it is in the
  page) or a click handler was attached to it (a script's e-stop).
- live_ms: the first event shown: <body data-link="up"> (static/js/link/honest.js), set when the
  event stream delivers.
- whole_ms: every static file, tile and basemap the page fetched has arrived and the load event ran.
- dcl_ms: DOMContentLoaded: every module script of the page ran; live.js opens the event stream then.
- floor_ms: the physical floor of this load: bytes ÷ the link's rate + 3 round trips (connect, the
  document, its subresources named up front). No load can beat it on this link.
The last line is one JSON object (as bench/link.py): the profile, and per page and cold/warm the
figures above.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from functools import partial
from pathlib import Path

import requests
from common import ROOT, free_port, machine, ros_env, stop_process

sys.path.insert(0, str(ROOT))
from rover_web.linkemu import LinkEmulator, profile  # noqa: E402

CHROMIUM = "/usr/bin/chromium"
PAGES = {
    "dashboard": "/",
    "waypoints": "/waypoints",
    "livemap": "/livemap",
    "robots": "/robots",
    "plot": "/plot?topic=/odom&field=twist.twist.linear.x",
    "recordings": "/recordings",
}
FILES = re.compile(r"^https?://[^/]+/(static|tiles|basemap)/")  # what "whole" waits for, as COLLECT
QUIET_S = 1.0  # nothing more asked for this long after the first event: the page is whole
KEYS = ("bytes", "wire_bytes", "requests", "ttfb_ms", "estop_ms", "live_ms", "whole_ms", "floor_ms", "dcl_ms")

# Runs before any of the page's scripts, in every document of the context.
OBSERVE = """
(() => {
  const pl = window.__pl = { estop: null, live: null };
  const now = () => performance.now();
  const add = EventTarget.prototype.addEventListener;
  EventTarget.prototype.addEventListener = function (type, fn, opts) {
    if (type === 'click' && pl.estop === null && this && this.id === 'estop-engage') pl.estop = now();
    return add.call(this, type, fn, opts);
  };
  const look = () => {
    const b = document.getElementById('estop-engage');
    if (pl.estop === null && b && b.type === 'submit' && b.form && b.form.method === 'post') pl.estop = now();
    if (pl.live === null && document.body && document.body.dataset.link === 'up') pl.live = now();
  };
  new MutationObserver(look).observe(document, { subtree: true, childList: true, attributes: true,
                                                 attributeFilter: ['data-link'] });
})();
"""
COLLECT = """
() => {
  const nav = performance.getEntriesByType('navigation')[0];
  const fetched = performance.getEntriesByType('resource')
    .filter((r) => /\\/(static|tiles|basemap)\\//.test(r.name)).map((r) => r.responseEnd);
  const timeline = performance.getEntriesByType('resource')
    .map((r) => [Math.round(r.startTime), Math.round(r.responseEnd), r.name.replace(/^https?:\\/\\/[^/]+/, '')]);
  return { ttfb: nav.responseStart, load: nav.loadEventEnd, last: Math.max(0, ...fetched),
           dcl: nav.domContentLoadedEventStart, estop: window.__pl.estop, live: window.__pl.live, timeline };
}
"""


class NetLog:
    """Chromium's own count of what went to the network for one page (DevTools protocol events)."""

    def __init__(self, cdp):
        self.cdp = cdp
        self.reset()
        cdp.on("Network.requestWillBeSent", self._sent)
        cdp.on("Network.requestServedFromCache", lambda e: self.cached.add(e["requestId"]))
        cdp.on("Network.loadingFinished", lambda e: self.finished.__setitem__(e["requestId"], e["encodedDataLength"]))
        cdp.on("Network.responseReceived", self._response)
        cdp.on("Network.loadingFailed", lambda e: self.finished.__setitem__(e["requestId"], 0))

    def reset(self):
        self.sent, self.cached, self.finished, self.streams = {}, set(), {}, set()

    def pending_files(self) -> list[str]:
        """Static files, tiles and basemaps asked for and not yet arrived (nor failed, nor cached)."""
        return [url for rid, url in self.sent.items() if FILES.search(url)
                and rid not in self.finished and rid not in self.cached]

    def _sent(self, e):
        if e["request"]["url"].startswith("http"):
            self.sent[e["requestId"]] = e["request"]["url"]

    def _response(self, e):
        if e["response"].get("mimeType") == "text/event-stream" or e["response"].get("fromDiskCache"):
            if e["response"].get("fromDiskCache"):
                self.cached.add(e["requestId"])
            else:
                self.streams.add(e["requestId"])

    def figures(self) -> tuple[int, int, list[str]]:
        network = [rid for rid in self.sent if rid not in self.cached]
        body = sum(self.finished.get(rid, 0) for rid in network if rid not in self.streams)
        return body, len(network), [self.sent[rid] for rid in network]


def strip_preload(route) -> None:
    """--no-preload: the page as it would be without its modulepreload links (the import map stays), to
    measure what naming every module up front saves. The document is fetched through the link as usual.
    Chromium caches nothing while requests are intercepted: only the cold figures mean anything."""
    if route.request.resource_type != "document":
        route.fallback()
        return
    response = route.fetch()
    body = re.sub(r'<link rel="modulepreload"[^>]*>\n?', "", response.text())
    headers = {k: v for k, v in response.headers.items() if k.lower() not in ("content-encoding", "content-length")}
    route.fulfill(status=response.status, headers=headers, body=body)


def start_app(tree: Path, env: dict, scratch: str) -> tuple[subprocess.Popen, str]:
    port = free_port()
    env = {**env, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1",
           "ROVER_WEB_DB_PATH": os.path.join(scratch, "bench.sqlite3"),
           "ROVER_WEB_RECORDINGS_DIR": os.path.join(scratch, "recordings"),
           "ROVER_WEB_SECRET_KEY": "page-load-bench-" + "k" * 32}
    proc = subprocess.Popen([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                             "--host", "127.0.0.1", "--port", str(port)], cwd=tree, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 90  # a first start compresses the static files once
    while True:
        try:
            if requests.get(url + "/api/status", timeout=1).ok:
                return proc, url
        except requests.RequestException:
            pass
        if time.monotonic() > deadline or proc.poll() is not None:
            stop_process(proc)
            raise RuntimeError(f"the app from {tree} did not start")
        time.sleep(0.2)


def measure(page, net: NetLog, emu: LinkEmulator, link, go, timeout_s: float) -> dict:
    net.reset()
    down_before = emu.counters()["down"]["bytes_passed"]
    go()
    page.wait_for_function("() => window.__pl && window.__pl.live !== null && document.readyState === 'complete'",
                           timeout=timeout_s * 1000)
    # Then every file the page asks for, the libraries it starts on its first event included, has
    # arrived and nothing more came for a moment. Not Playwright's "networkidle": that also counts a
    # quiet moment before the first event (a bundled page reaches one), after which MapLibre was missed.
    deadline, quiet_since = time.monotonic() + timeout_s, None
    while time.monotonic() < deadline:
        if net.pending_files():
            quiet_since = None
        elif quiet_since is None:
            quiet_since = time.monotonic()
        elif time.monotonic() - quiet_since >= QUIET_S:
            break
        page.wait_for_timeout(50)  # the browser's events keep coming meanwhile
    got = page.evaluate(COLLECT)
    wire = emu.counters()["down"]["bytes_passed"] - down_before
    body, count, urls = net.figures()
    floor = body / link.rate_bytes_per_s * 1000 + 3 * link.rtt_ms
    return {"bytes": body, "wire_bytes": wire, "requests": count, "ttfb_ms": round(got["ttfb"]),
            "estop_ms": None if got["estop"] is None else round(got["estop"]),
            "live_ms": round(got["live"]), "whole_ms": round(max(got["load"], got["last"])),
            "floor_ms": round(floor), "static_requests": sum("/static/" in u for u in urls), "urls": urls,
            "dcl_ms": round(got["dcl"]), "timeline": got["timeline"]}


def run(args) -> dict:
    from playwright.sync_api import sync_playwright

    link = (profile("custom", rate_kbps=1_000_000, delay_ms=0, buffer_kb=4096) if args.profile == "loopback"
            else profile(args.profile))
    tree = Path(args.tree).resolve()
    pages = [p for p in args.pages.split(",") if p]
    unknown = [p for p in pages if p not in PAGES]
    if unknown:
        raise SystemExit(f"unknown page(s) {unknown}; choose from {', '.join(PAGES)}")
    scratch = tempfile.TemporaryDirectory(prefix="rover_web-bench-page-load-")
    env = ros_env()
    head = git_head(tree)
    print(f"# page load bench on {machine()} (load {os.getloadavg()[0]:.1f}): {link.describe()}; "
          f"app from {tree} at {head}; ROS domain {env['ROS_DOMAIN_ID']}", flush=True)
    sim = subprocess.Popen([sys.executable, "-m", "rover_web.sim"], cwd=ROOT, env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    app = emu = None
    results: dict[str, dict] = {}
    try:
        app, direct = start_app(tree, env, scratch.name)
        emu = LinkEmulator(link, "127.0.0.1:0", ("127.0.0.1", int(direct.rsplit(":", 1)[1])), seed=args.seed).start()
        url = f"http://127.0.0.1:{emu.port}"
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=[
                "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"])
            for name in pages:
                context = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True)
                context.add_init_script(OBSERVE)
                if args.no_preload:
                    context.route("**/*", strip_preload)
                page = context.new_page()
                cdp = context.new_cdp_session(page)
                cdp.send("Network.enable")
                net = NetLog(cdp)
                target = url + PAGES[name]
                results[name] = {}
                try:
                    wait_ms = args.timeout * 1000
                    results[name]["cold"] = measure(page, net, emu, link, partial(
                        page.goto, target, wait_until="commit", timeout=wait_ms), args.timeout)
                    time.sleep(1.0)
                    results[name]["warm"] = measure(page, net, emu, link, partial(
                        page.reload, wait_until="commit", timeout=wait_ms), args.timeout)
                except Exception as exc:  # noqa: BLE001 - one page failing still reports the others
                    results[name]["error"] = f"{type(exc).__name__}: {str(exc).splitlines()[0][:200]}"
                finally:
                    context.close()
                for kind in ("cold", "warm"):
                    if kind in results[name]:
                        r = results[name][kind]
                        print(f"{name:10s} {kind}: {r['bytes'] / 1000:8.1f} kB ({r['wire_bytes'] / 1000:.1f} kB on "
                              f"the wire with streams) in {r['requests']:3d} requests ({r['static_requests']} static); "
                              f"TTFB {r['ttfb_ms']} ms, e-stop {r['estop_ms']} ms, live {r['live_ms']} ms, "
                              f"whole {r['whole_ms']} ms; floor {r['floor_ms']} ms", flush=True)
                        urls, timeline = r.pop("urls"), r.pop("timeline")
                        if args.timeline:
                            print(f"    DOMContentLoaded {r['dcl_ms']} ms; started → ended ms, each request:")
                            for started, ended, what in sorted(timeline):
                                print(f"    {started:6d} → {ended:6d}  {what[:110]}")
                        if args.list_requests:
                            paths = Counter(re.sub(r"^https?://[^/]+|\?.*$", "", u) for u in urls)
                            print("    " + ", ".join(f"{p} ×{n}" if n > 1 else p for p, n in paths.most_common()))
                if "error" in results[name]:
                    print(f"{name:10s} failed: {results[name]['error']}", flush=True)
            browser.close()
    finally:
        if emu is not None:
            emu.stop()
        if app is not None:
            stop_process(app)
        stop_process(sim)
        scratch.cleanup()
    return {"bench": "page_load", "profile": link.name, "link": link.describe(), "tree": str(tree), "commit": head,
            "seed": args.seed, "preload": not args.no_preload, "machine": machine(),
            "load": round(os.getloadavg()[0], 1), "pages": results}


def git_head(tree: Path) -> str:
    try:
        return subprocess.run(["git", "-C", str(tree), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip() or "?"
    except OSError:
        return "?"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--profile", default="wifi-edge",
                        choices=["radio", "wifi-edge", "starlink", "wifi-good", "loopback"])
    parser.add_argument("--pages", default=",".join(PAGES), help="comma-separated: " + ", ".join(PAGES))
    parser.add_argument("--tree", default=str(ROOT), help="the checkout whose app is measured (default: this one)")
    parser.add_argument("--timeout", type=float, default=60.0, help="per load, seconds")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-preload", action="store_true",
                        help="strip the pages' modulepreload links (what naming the modules up front saves); "
                             "cold figures only: intercepting requests turns Chromium's cache off")
    parser.add_argument("--timeline", action="store_true",
                        help="print each load's requests with when they started and ended (Resource Timing)")
    parser.add_argument("--list-requests", action="store_true",
                        help="print each load's requests by path (what went to the network, and how often)")
    print(json.dumps(run(parser.parse_args())), flush=True)


if __name__ == "__main__":
    main()
