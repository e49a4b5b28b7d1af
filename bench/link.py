"""rover_web over an emulated field link: teleop, e-stop, video and events through the link emulator.

    .venv/bin/python bench/link.py --profile wifi-edge --camera on [--video mjpeg|webrtc] [--adapt on|off]
                                   [--teleop websocket|datachannel] [--seconds 60] [--estops 10] [--seed 1]
                                   [--rate-kbps N --delay-ms N ...: the profile's figures, as the emulator's CLI]

Starts the demo's simulator (`python -m rover_web.sim`: rover, buoy, drone, camera 640×480 at
30 Hz) and the app (`flask run`, bench/common.Server) in their own processes, and a LinkEmulator
(rover_web/linkemu) in this one, in front of the app. Every client below talks to the app through
the emulator only; the rclpy subscriber watching /cmd_vel is on the robot's side (DDS, no link).

1. Hold phase, `--seconds`: a teleop WebSocket holds the stick at 25 Hz (a distinct value per
   frame); with `--camera on` an MJPEG viewer reads /stream?topic=/camera/image_raw; an SSE client
   reads /api/events?channels=odom.
   - teleop_p50/p99_ms: the frame written to the socket → the first /cmd_vel Twist carrying its
     value, seen by bench/cmd_vel_subscriber.py in its own process (CLOCK_MONOTONIC both). It
     includes the uplink's delay and queueing, not the way back.
   - spurious_stops_per_min: zero Twists following a non-zero one while the stick is held, per
     minute held, leaving out those from an outage's start to 1 s after its end (an outage must
     stop the robot).
   - outage_zero_ms: for each outage that begins in the hold, its start (the emulator's schedule)
     → the first zero Twist at the subscriber; nothing the operator sends arrives in an outage, so
     this must be within the app's deadman bound (deadman_max_ms) plus a repeater period.
   - video_fps, frame_age_p50/p99_ms: frames received per second; age = the frame's last byte
     in this process (wall clock) − the time code the simulated camera drew into it (its wall
     clock at capture, rover_web/sim/timecode.py, read from the decoded JPEG): glass to glass.
   - event_age_p99_ms: odom SSE frames, kernel arrival time (wall) − the Odometry header stamp
     (the simulator's wall clock at publish).
2. E-stop phase (`--estops` times, for at most 120 s; the stick released, camera and events still
   flowing): POST /api/estop {"engaged": true} timed to its answer (estop_rtt_*), then a timed
   release. A POST unanswered after 30 s counts as 30 s and is counted (estop_timeouts).
--video webrtc: the viewer is an aiortc WHEP client (bench/link_webrtc.py) whose media and data
channel cross the emulator's UDP path (SDP candidates rewritten; `webrtc_route` in the JSON names
the pair it used); frames are decoded and their time code read the same way. --teleop datachannel
holds the stick over that session's `teleop` data channel instead of the WebSocket.
link_rtt_ms is the profile's nominal round trip (2 × one-way delay); link_rtt_measured_ms is the
median of 10 GET /api/estop on the idle link before the hold phase (a small request and answer).
"""

from __future__ import annotations

import argparse
import io
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import requests
from common import ROOT, WALL_MINUS_MONOTONIC, Server, SseFleet, machine, percentile, ros_env, stop_process, wait_for

sys.path.insert(0, str(ROOT))
from link_figures import (  # noqa: E402
    OUTAGE_GRACE_S,
    VALUES,
    deadman_bound_s,
    down_since,
    first_outage_in,
    outage_zeros,
    spurious_stops,
    stick_value,
    teleop_latencies,
)
from link_webrtc import ChannelSocket, LinkWhep  # noqa: E402
from teleop import Heard, Subscriber, connect, encoded, frame, hang_up  # noqa: E402

from rover_web import config as config_module  # noqa: E402
from rover_web.linkemu import PROFILES, LinkEmulator, profile  # noqa: E402
from rover_web.linkemu.profiles import CUSTOM_FIELDS  # noqa: E402
from rover_web.sim import timecode  # noqa: E402
from tests.support.mjpeg import MjpegClient  # noqa: E402

TOPIC = "/camera/image_raw"
STICK_HZ = 25.0


class Stick(threading.Thread):
    """The operator's thumb on the stick: a frame every 1/STICK_HZ s, each a new value, with the
    epoch the server last said (a deadman stop starts a new one), and `seq` and `t` as the Drive
    card sends them: the server's hold, ramp and link figures go by those, so frames without them
    would measure another rule than the page gets."""

    def __init__(self, ws, send=None):
        super().__init__(daemon=True)
        self.ws = ws  # bench/teleop.connect's WebSocket, or link_webrtc.ChannelSocket: .heard, .send(text)
        self._send = send or (lambda text: ws.sock.sendall(encoded(text)))  # pre-encoded frame: no masking cost
        self.sent: list[tuple[float, int]] = []  # (monotonic, value index)
        self.lost_at: float | None = None  # when the socket failed under the stick, if it did
        self.running = threading.Event()
        self.running.set()

    def run(self) -> None:
        period, start, i = 1 / STICK_HZ, time.monotonic(), 0
        while self.running.is_set():
            while (wait := start + i * period - time.monotonic()) > 0:
                time.sleep(wait)
            t = time.monotonic()
            # t counts from the stick's start, as performance.now() counts from the page's
            text = frame(stick_value(i), epoch=self.ws.heard.epoch, seq=i + 1, t_ms=(t - start) * 1000)
            try:
                self._send(text)
            except OSError:
                self.lost_at = time.monotonic()  # the server closed it: reported, not retried
                return
            self.sent.append((t, i % VALUES))
            i += 1

    def release(self) -> None:
        self.running.clear()
        self.join(5)
        if self.lost_at is None:
            try:
                self._send(json.dumps({"stop": True}))
            except OSError:
                self.lost_at = time.monotonic()


class Viewer:
    """An MJPEG viewer through the link; a thread decodes each frame's time code as frames arrive.
    With `ack`, it acknowledges the bytes it receives as the camera card's page does (GET
    /stream?ack=1, POST /api/camera/viewers/<id>/ack through the same link, one ack in flight):
    only when the server names the stream (adaptation on; an older build ignores ack=1)."""

    def __init__(self, url: str, ack: bool = True):
        self.client = MjpegClient(f"{url}/stream?topic={TOPIC}" + ("&ack=1" if ack else ""), ack=ack)
        self.samples: list[tuple[float, float | None, int]] = []  # (arrival monotonic, age ms or None, bytes)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._decode, daemon=True)
        self._thread.start()

    def _decode(self) -> None:
        import numpy as np
        from PIL import Image

        while not self._stop.wait(0.1):
            with self.client._cond:  # the reader appends under this lock: take what it has so far
                frames, self.client.frames = self.client.frames, []
            for t_arrived, _headers, data in frames:
                try:
                    pixels = np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))
                    arrived_ms = (t_arrived + WALL_MINUS_MONOTONIC) * 1000
                    stamp = timecode.read(pixels, now_ms=int(arrived_ms))
                except OSError:
                    stamp = None
                self.samples.append((t_arrived, None if stamp is None else arrived_ms - stamp, len(data)))

    def window(self, start: float, end: float) -> list[tuple[float, float | None, int]]:
        return [s for s in self.samples if start <= s[0] <= end]

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self.client.close()


class Events(threading.Thread):
    """An SSE client on the odom channel through the link: (arrival monotonic, age ms) per frame."""

    def __init__(self, url: str):
        super().__init__(daemon=True)
        self.fleet = SseFleet(url, "/api/events?channels=odom")
        self.ages: list[tuple[float, float]] = []
        self.running = threading.Event()
        self.running.set()

    def run(self) -> None:
        def on_event(_woken, arrived, name, data):
            if name == "odom" and isinstance(data.get("stamp"), (int, float)):
                self.ages.append((arrived, ((arrived + WALL_MINUS_MONOTONIC) - data["stamp"]) * 1000))

        while self.running.is_set():
            self.fleet.poll(0.5, on_event)

    def close(self) -> None:
        self.running.clear()
        self.join(5)
        self.fleet.close()


def ms(values: list[float], p: float) -> float | None:
    return round(percentile(values, p), 1) if values else None


ESTOP_TIMEOUT_S = 30.0
ESTOP_BUDGET_S = 120.0  # the phase stops starting trials after this long (a clogged link takes ~30 s each)


def estop_trials(url: str, n: int) -> tuple[list[float], list[float], int, list[tuple[float, float]]]:
    """n × (engage, then release), each POST timed; a Session keeps its connection, as a page does.
    A POST unanswered after ESTOP_TIMEOUT_S counts as that long (and is counted): the p99 is then a
    lower bound. The last list: when each engage began and ended (to tell those a stall held)."""
    engage, release, timeouts, spans = [], [], 0, []
    start = time.monotonic()

    def timed(session, engaged: bool) -> float:
        nonlocal timeouts
        t0 = time.monotonic()
        try:
            session.post(url + "/api/estop", json={"engaged": engaged, "by": "bench"},
                         timeout=ESTOP_TIMEOUT_S).raise_for_status()
        except requests.Timeout:
            timeouts += 1
            return ESTOP_TIMEOUT_S * 1000
        return (time.monotonic() - t0) * 1000

    with requests.Session() as session:
        for _ in range(n):
            if time.monotonic() - start > ESTOP_BUDGET_S:
                break
            t0 = time.monotonic()
            engage.append(timed(session, True))
            spans.append((t0, time.monotonic()))
            time.sleep(0.3)
            release.append(timed(session, False))
            time.sleep(0.7)
    return engage, release, timeouts, spans


def link_rtt(url: str) -> float:
    times = []
    with requests.Session() as session:
        session.get(url + "/api/estop", timeout=30)  # the connection, once
        for _ in range(10):
            t0 = time.monotonic()
            session.get(url + "/api/estop", timeout=30).raise_for_status()
            times.append((time.monotonic() - t0) * 1000)
    return statistics.median(times)


def adapt_setting(adapt: str | None) -> tuple[dict[str, str], str]:
    """ROVER_WEB_CAMERA_ADAPT when this build has it (issue 25's video adaptation)."""
    if adapt is None:
        return {}, "default"
    if not any(s.name == "CAMERA_ADAPT" for s in config_module.SETTINGS):
        print(f"# --adapt {adapt}: this build has no ROVER_WEB_CAMERA_ADAPT; running without it", flush=True)
        return {}, "n/a"
    return {"ROVER_WEB_CAMERA_ADAPT": "true" if adapt == "on" else "false"}, adapt


def bench_profile(name: str, overrides: dict):
    """A named profile, or `loopback`: no limits at all, what the machine alone costs (a control);
    either with the link flags given (as `flask link-emulator` takes them; `custom` is made of them)."""
    if name == "loopback":
        return profile("custom", **{"rate_kbps": 1_000_000, "delay_ms": 0, "buffer_kb": 4096,
                                    **{k: v for k, v in overrides.items() if v is not None}})
    return profile(name, **overrides)


def run(args) -> dict:
    link = bench_profile(args.profile, {k: getattr(args, k) for k in CUSTOM_FIELDS})
    load_before = os.getloadavg()[0]
    scratch = tempfile.TemporaryDirectory(prefix="rover_web-bench-link-")
    extra, adapt = adapt_setting(args.adapt)
    webrtc = args.video == "webrtc" and args.camera == "on"
    if webrtc:
        extra["ROVER_WEB_WEBRTC_HOST_ADDRESSES"] = "127.0.0.1"  # the answer's one candidate (link_webrtc.py)
    extra.update(dict(s.split("=", 1) for s in args.set))  # e.g. --set ROVER_WEB_WEBRTC_LINK_SHARE=0.6
    env = ros_env(ROVER_WEB_DB_PATH=os.path.join(scratch.name, "bench.sqlite3"), **extra)
    print(f"# link bench on {machine()}: {link.describe()}; camera {args.camera} ({args.video}), adapt {adapt}, "
          f"teleop over {args.teleop}; "
          f"ROS domain {env['ROS_DOMAIN_ID']}", flush=True)
    sim = subprocess.Popen([sys.executable, "-m", "rover_web.sim"], cwd=ROOT, env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    server = sub = emu = ws = viewer = events = server_said_video = None
    try:
        server = Server(env)
        sub = Subscriber(env)
        # The UDP relay's target is the server's ICE port, known only from the WHEP answer: LinkWhep
        # sets it before the first datagram (port 9, discard, until then).
        udp = {"udp_listen": "127.0.0.1:0", "udp_target": ("127.0.0.1", 9)} if webrtc else {}
        t_emulator = time.monotonic()
        emu = LinkEmulator(link, "127.0.0.1:0", ("127.0.0.1", server.port), seed=args.seed, **udp).start()
        url = f"http://127.0.0.1:{emu.port}"
        measured_rtt = link_rtt(url)
        events = Events(url)
        events.start()
        wait_for(lambda: events.ages, 60, "the first odom event through the link")
        if args.teleop == "websocket":
            ws = connect(url)  # before the video: its handshake would otherwise queue behind seconds of frames
        if webrtc:
            viewer = LinkWhep(emu, url, TOPIC, teleop=args.teleop == "datachannel")
        elif args.camera == "on":
            viewer = Viewer(url, ack=args.adapt != "off")  # a page acknowledges when the server adapts
        if viewer is not None:
            wait_for(lambda: viewer.samples, 60, "the first camera frame through the link")
        if args.teleop == "datachannel":
            ws = ChannelSocket(viewer, Heard)
            stick = Stick(ws, send=ws.send)
        else:
            stick = Stick(ws)
        mark = sub.mark()
        stick.start()
        time.sleep(2.0)  # settle: the first frames, the video's queue filling
        t_start = time.monotonic()
        if link.outage_every_s and link.outage_s and \
                first_outage_in(link, t_emulator, t_start, t_start + args.seconds) is None:
            print(f"# the hold ends before the link's first outage ({link.outage_every_s / 2:g} s after the "
                  f"emulator started): outage_zero_ms will be empty; give --seconds "
                  f"{math.ceil(t_emulator + link.outage_every_s / 2 + link.outage_s - t_start)} or more", flush=True)
        time.sleep(args.seconds)
        t_end = time.monotonic()
        if webrtc:  # what the server's adaptation chose by the end of the hold (asked on loopback, not the link)
            session = requests.get(server.url + "/api/camera/whep", timeout=10).json()["sessions"]
            keys = ("level", "width", "height", "fps", "target_bps", "remb_bps", "loss_keyframes", "encoder_restarts",
                    "frames_held")
            server_said_video = {k: session[0].get(k) for k in keys} if session else None
        stick.release()
        twists = sub.since(mark)
        said = dict(ws.heard.counts)
        t_estop = time.monotonic()
        engage, release, estop_timeouts, engage_spans = estop_trials(url, args.estops)
        t_estop_end = time.monotonic()
        # the deadman's zero for an outage near the hold's end comes after the release
        twists_after = sub.since(mark)
        windows = emu.windows()
        counters = emu.counters()
        route = viewer.route() if webrtc else None
        sizes = viewer.size_shares(t_start, t_end) if webrtc else None
        jitter = {"holes_given_up": viewer.jitter.given_up, "frames_dropped": viewer.jitter.dropped} if webrtc else None
    finally:
        for part in (viewer, events):
            if part is not None:
                part.close()
        if ws is not None and args.teleop == "websocket":
            hang_up(ws)
        if emu is not None:
            emu.stop()
        if sub is not None:
            sub.stop()
        if server is not None:
            server.stop()
        stop_process(sim)
        scratch.cleanup()

    held_s = t_end - t_start
    outages = [(a, b) for a, b, kind in windows if kind == "outage"]
    latencies = [x * 1000 for x in teleop_latencies([s for s in stick.sent if t_start <= s[0] <= t_end],
                                                    twists)]
    stops_out, stops_in = spurious_stops(twists, t_start, t_end, outages)
    zeros, moves = outage_zeros(twists_after, t_start, t_end, outages)
    lead_ms = [round((a - down_since(a, windows)) * 1000, 1) for a, _ in outages if t_start <= a <= t_end]
    frames = viewer.window(t_start, t_end) if viewer else []
    ages = [age for _, age, _ in frames if age is not None]
    ages_outside = [age for t, age, _ in frames  # issue 26's radio target is "outside outages"
                    if age is not None and not any(a <= t <= b + OUTAGE_GRACE_S for a, b in outages)]
    # A stall holds every byte: frames made during it arrive that much older whatever the video does.
    ages_clear = [age for t, age, _ in frames
                  if age is not None and not any(a <= t <= b + OUTAGE_GRACE_S for a, b, _ in windows)]
    estop_frames = viewer.window(t_estop, t_estop_end) if viewer else []
    # An e-stop the link itself held (a stall or an outage overlapping it) measures the link, not
    # what stood in front of the e-stop in its queue.
    estop_clear = [d for (t0, t1), d in zip(engage_spans, engage, strict=True)
                   if not any(a < t1 and t0 < b for a, b, _ in windows)]
    event_ages = [age for t, age in events.ages if t_start <= t <= t_end]
    if args.frames_out:  # every frame's arrival (s into the hold), age and size, and the link's windows
        with open(args.frames_out, "w") as out:
            json.dump({"frames": [(round(t - t_start, 3), age, size) for t, age, size in frames],
                       "windows": [(round(a - t_start, 3), round(b - t_start, 3), kind) for a, b, kind in windows]},
                      out)
    result = {
        "profile": args.profile,
        "camera": args.camera,
        "video": args.video,
        "adapt": adapt,
        "teleop": args.teleop,
        "seconds": round(held_s, 1),
        "link": link.describe(),
        "link_rtt_ms": link.rtt_ms,
        "link_rtt_measured_ms": round(measured_rtt, 1),
        "teleop_p50_ms": ms(latencies, 50),
        "teleop_p99_ms": ms(latencies, 99),
        "teleop_frames_matched": f"{len(latencies)}/{sum(1 for s in stick.sent if t_start <= s[0] <= t_end)}",
        "spurious_stops_per_min": round(stops_out / (held_s / 60), 2),
        "stops_in_outages": stops_in,
        # each outage begun while the stick was held: its start → the first zero Twist on /cmd_vel
        "outage_zero_ms": zeros,
        "outage_zero_max_ms": max(zeros, key=lambda z: math.inf if z is None else z) if zeros else None,
        "outage_moves_after_zero": sum(moves),  # non-zero Twists after that zero, before the outage ended
        "outage_down_before_ms": lead_ms,  # how long a stall ran into each outage: the link was down that much earlier
        "deadman_max_ms": round(deadman_bound_s(env, config_module.SETTINGS) * 1000),
        "server_said": said,
        "teleop_socket_lost_at_s": None if stick.lost_at is None else round(stick.lost_at - t_start, 1),
        "estop_trials": len(engage),
        "estop_timeouts": estop_timeouts,
        "estop_rtt_p50_ms": ms(engage, 50),
        "estop_rtt_p99_ms": ms(engage, 99),
        "estop_release_p99_ms": ms(release, 99),
        "estop_rtt_p99_outside_stalls_ms": ms(estop_clear, 99),
        "estop_trials_outside_stalls": len(estop_clear),
        "video_fps": round(len(frames) / held_s, 2),
        # MJPEG: JPEG bytes; WebRTC: RTP payload bytes
        "video_kbps": round(sum(b for _, _, b in frames) * 8 / held_s / 1000, 1),
        "frames_unreadable": sum(1 for _, age, _ in frames if age is None),
        "frame_age_p50_ms": ms(ages, 50),
        "frame_age_p99_ms": ms(ages, 99),
        "frame_age_p99_outside_outages_ms": ms(ages_outside, 99),  # frames arriving in an outage or 1 s after left out
        "frame_age_p99_outside_stalls_ms": ms(ages_clear, 99),  # ... and in a stall or 1 s after
        "video_fps_during_estops": round(len(estop_frames) / max(1e-9, t_estop_end - t_estop), 2),
        "event_age_p50_ms": ms(event_ages, 50),
        "event_age_p99_ms": ms(event_ages, 99),
        "events_per_s": round(len(event_ages) / held_s, 2),
        "stalls": counters["stalls"],
        "outages": counters["outages"],
        "down_queue_peak_kb": round(counters["down"]["queue_peak"] / 1000, 1),
        "seed": emu.seed,
        # WebRTC: the client's nominated ICE pairs (the remote must be the emulator's UDP port) and
        # the UDP bytes that crossed the emulator towards the client (counters are per direction, TCP + UDP).
        "webrtc_route": route,
        "webrtc_sizes": sizes,  # decoded frame sizes in the hold, with their share of frames
        "webrtc_server": server_said_video if webrtc else None,
        # the viewer's jitter buffer (bench/browser_jitter.py): lost packets given up, frames dropped until a keyframe
        "webrtc_jitter": jitter,
        "emulator_udp_port": emu.udp_port if webrtc else None,
        "server_ice_port": viewer.server_port if webrtc else None,
        "load_avg": [round(load_before, 1), round(os.getloadavg()[0], 1)],  # the machine's, start and end
    }
    return result


def table(r: dict) -> str:
    def f(v, unit=""):
        return "—" if v is None else f"{v}{unit}"
    rows = [
        ("link", f"{r['profile']}: nominal RTT {r['link_rtt_ms']:g} ms, measured {r['link_rtt_measured_ms']} ms; "
                 f"{r['stalls']} stalls, {r['outages']} outages in the run; downlink queue peak "
                 f"{r['down_queue_peak_kb']} kB; load average {r['load_avg'][0]} → {r['load_avg'][1]}"),
        (f"teleop ({r['teleop']}) frame → /cmd_vel", f"p50 {f(r['teleop_p50_ms'], ' ms')}, "
                                                     f"p99 {f(r['teleop_p99_ms'], ' ms')} "
                                    f"({r['teleop_frames_matched']} frames matched)"),
        ("spurious stops", f"{r['spurious_stops_per_min']} per minute held ({r['stops_in_outages']} more "
                           f"during outages); server said {r['server_said'] or 'nothing'}"
                           + ("" if r["teleop_socket_lost_at_s"] is None
                              else f"; the teleop socket was lost {r['teleop_socket_lost_at_s']} s into the hold")),
        ("outage → zero /cmd_vel", ", ".join(f(z, " ms") for z in r["outage_zero_ms"])
         + f" (bound {r['deadman_max_ms']} ms; the link was down (a stall) "
           + ", ".join(f"{d:g}" for d in r["outage_down_before_ms"]) + " ms before it); "
           f"{r['outage_moves_after_zero']} non-zero Twists after it in the outage"
         if r["outage_zero_ms"] else "no outage began in the hold"),
        ("e-stop POST round trip", f"p50 {f(r['estop_rtt_p50_ms'], ' ms')}, p99 {f(r['estop_rtt_p99_ms'], ' ms')}; "
                                   f"release p99 {f(r['estop_release_p99_ms'], ' ms')} ({r['estop_trials']} trials"
                                   + (f", {r['estop_timeouts']} POSTs unanswered after {ESTOP_TIMEOUT_S:g} s"
                                      if r["estop_timeouts"] else "") + "); "
                                   f"p99 outside stalls and outages {f(r['estop_rtt_p99_outside_stalls_ms'], ' ms')} "
                                   f"({r['estop_trials_outside_stalls']} trials)"),
        ("video", f"{r['video']}: {r['video_fps']} fps, {r['video_kbps']} kbit/s, "
                  f"frame age p50 {f(r['frame_age_p50_ms'], ' ms')}"
                  f", p99 {f(r['frame_age_p99_ms'], ' ms')} (outside outages "
                  f"{f(r['frame_age_p99_outside_outages_ms'], ' ms')}, outside stalls and outages "
                  f"{f(r['frame_age_p99_outside_stalls_ms'], ' ms')}; {r['frames_unreadable']} unreadable)"),
        ("odom events", f"{r['events_per_s']} /s, age p50 {f(r['event_age_p50_ms'], ' ms')}, "
                        f"p99 {f(r['event_age_p99_ms'], ' ms')}"),
    ]
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--profile", choices=[*PROFILES, "custom", "loopback"], default="wifi-edge",
                        help="the link; loopback: the emulator with no limits, a control for the machine's own noise")
    parser.add_argument("--camera", choices=("on", "off"), default="on")
    parser.add_argument("--video", choices=("mjpeg", "webrtc"), default="mjpeg")
    parser.add_argument("--teleop", choices=("websocket", "datachannel"), default="websocket",
                        help="drive over WS /ws/teleop, or over the WHEP session's `teleop` data channel "
                             "(needs --video webrtc --camera on)")
    parser.add_argument("--adapt", choices=("on", "off"), default=None,
                        help="sets ROVER_WEB_CAMERA_ADAPT on the app (default: the app's default)")
    parser.add_argument("--seconds", type=float, default=60.0, help="how long the stick is held")
    parser.add_argument("--estops", type=int, default=10, help="e-stop engage/release trials after the hold")
    parser.add_argument("--set", action="append", default=[], metavar="ROVER_WEB_NAME=VALUE",
                        help="an app setting for this run (repeatable)")
    parser.add_argument("--frames-out", metavar="FILE", help="write every frame's arrival, age and size (JSON)")
    parser.add_argument("--seed", type=int, default=1, help="the emulator's random seed (stalls, jitter)")
    flags = parser.add_argument_group("the link", "override the profile's figures, as `flask link-emulator` "
                                      "does; --profile custom starts from a plain 10 Mbit/s link")
    for name in CUSTOM_FIELDS:
        if name == "reset_on_outage":
            flags.add_argument("--reset-on-outage", action="store_true", default=None)
        else:
            flags.add_argument("--" + name.replace("_", "-"), type=float, metavar="N")
    args = parser.parse_args()
    if args.teleop == "datachannel" and (args.video != "webrtc" or args.camera != "on"):
        parser.error("--teleop datachannel needs --video webrtc --camera on (the channel is the WHEP session's)")
    try:
        bench_profile(args.profile, {k: getattr(args, k) for k in CUSTOM_FIELDS})
    except (ValueError, TypeError) as exc:
        parser.error(str(exc))
    result = run(args)
    print(table(result), flush=True)
    print(json.dumps(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
