"""Teleop: WebSocket frame -> Twist on /cmd_vel in a separate rclpy process; close -> zero; rate jitter.

    .venv/bin/python bench/teleop.py [--frames 2000] [--block 250] [--trials 100] [--hold-s 10]
                                     [--overlays 10 | --recording]

1. frame -> topic: `--frames` joystick frames at 40 Hz, each a new value, from a WebSocket client
   to the app (`flask run` in its own process); latency is the moment the (already framed and
   masked) frame is written to the socket to its arrival in the subscriber process (both
   CLOCK_MONOTONIC). Server CPU and RSS over the run. In blocks of `--block` frames that
   alternate with the baseline's (4.), so both are measured in the same minutes: on a shared
   virtual machine rclpy -> rclpy alone drifts by a tenth of a millisecond from minute to minute.
2. close -> zero: `--trials` times, drive, then send the WebSocket close frame; time to the zero Twist.
3. publish-rate jitter: hold one value for `--hold-s` with keep-alives every 100 ms (as the page
   does), so the server's repeater alone sets the rate; intervals between its Twists at the
   subscriber, from the first repeat on.
4. baseline: the same number of Twists at 40 Hz from a plain rclpy publisher in this process to
   a subscriber process of the same kind, measured the same way (what rclpy -> rclpy costs on this
   machine), in the blocks between the app's. The app's own share is printed as the difference.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time

from common import (
    ROOT,
    Server,
    SseFleet,
    machine,
    percentile,
    ros_env,
    start_peer,
    stop_process,
    summary_ms,
    wait_for_topic,
)
from metrics import Scraper

MAX_LINEAR = 5.0
RATE_HZ = 40.0


class Subscriber:
    """bench/cmd_vel_subscriber.py in its own process; every Twist with its arrival time."""

    def __init__(self, env: dict, topic: str = "/cmd_vel"):
        self.proc = subprocess.Popen([sys.executable, str(ROOT / "bench" / "cmd_vel_subscriber.py"), "--topic", topic],
                                     env=env, stdout=subprocess.PIPE, text=True, bufsize=1)
        if self.proc.stdout.readline().strip() != "ready":
            raise RuntimeError("subscriber did not start")
        self.messages: list[tuple[float, float, float]] = []
        self._cond = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            t_ns, lin, ang = line.split()
            with self._cond:
                self.messages.append((int(t_ns) * 1e-9, float(lin), float(ang)))
                self._cond.notify_all()

    def mark(self) -> int:
        with self._cond:
            return len(self.messages)

    def since(self, mark: int) -> list[tuple[float, float, float]]:
        with self._cond:
            return self.messages[mark:]

    def wait_for(self, predicate, mark: int = 0, timeout: float = 5.0) -> tuple[float, float, float]:
        deadline = time.monotonic() + timeout
        with self._cond:
            i = mark
            while True:
                while i < len(self.messages):
                    if predicate(self.messages[i]):
                        return self.messages[i]
                    i += 1
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError("no matching Twist")
                self._cond.wait(remaining)

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            self.proc.kill()


class Heard:
    """What the server said on a bench socket: its current epoch, and how often it stopped or refused."""

    def __init__(self, epoch: int):
        self.epoch = epoch
        self.counts: dict[str, int] = {}

    def note(self, message: dict) -> None:
        if "epoch" in message:
            self.epoch = message["epoch"]
        key = message.get("error") if message.get("type") == "error" else message.get("reason")
        if key in ("deadman", "stale_epoch", "not_in_control", "estop_engaged", "bad_input"):
            self.counts[key] = self.counts.get(key, 0) + 1


def connect(url: str):
    """A WebSocket that, like a browser, keeps reading (which answers the server's pings) and
    follows the epoch, so a deadman stop costs the frames sent before the client heard of it and
    not the rest of the run."""
    import websocket

    ws = websocket.create_connection(url.replace("http://", "ws://") + "/ws/teleop?name=bench", timeout=10)
    hello = json.loads(ws.recv())
    assert hello["type"] == "hello"
    ws.heard = Heard(hello["epoch"])

    def drain() -> None:
        try:
            while True:
                opcode, data = ws.recv_data_frame(control_frame=True)
                if opcode == websocket.ABNF.OPCODE_CLOSE:
                    return
                if opcode == websocket.ABNF.OPCODE_TEXT:
                    ws.heard.note(json.loads(data.data))
        except Exception:
            pass

    ws.settimeout(None)
    threading.Thread(target=drain, daemon=True).start()
    return ws


def hang_up(ws) -> None:
    try:
        ws.send_close()
    except Exception:
        pass
    time.sleep(0.05)
    ws.shutdown()


def frame(linear: float, angular: float = 0.0, epoch: int = 0,
          seq: int | None = None, t_ms: float | None = None) -> str:
    """A drive frame. With `seq` and `t_ms` it is the Drive card's (static/js/teleop.js): the server
    dates its freshness, jitter and stalls from `t_ms` and drops it if `seq` is not newer, so a
    bench that leaves them out measures the rule for clients without them, not the page's. This
    loopback bench leaves them out: it builds its frames seconds before sending them."""
    body = {"linear": linear, "angular": angular, "epoch": epoch}
    if seq is not None:
        body.update(source="joystick", seq=seq, t=round(t_ms, 1))
    return json.dumps(body)


def on_grid(n: int, rate_hz: float, send) -> list[float]:
    """Call send(i) on a fixed 1/rate_hz grid; returns the time just before each call."""
    period = 1.0 / rate_hz
    start = time.monotonic() + 0.05
    times = []
    for i in range(n):
        while (wait := start + i * period - time.monotonic()) > 0:
            time.sleep(wait)
        times.append(time.monotonic())
        send(i)
    return times


def value(i: int, n: int) -> float:
    """A distinct joystick fraction per frame, so each frame is published at once and recognisable."""
    return round((i % n + 1) / (n + 1), 6)


def match_latencies(sub: Subscriber, mark: int, sent: dict[int, float], n: int, scale: float) -> list[float]:
    """Latency of each frame index in `sent` (index -> send time), from the first Twist carrying its value."""
    first: dict[int, float] = {}
    for t, lin, _ in sub.since(mark):
        i = round(lin / scale * (n + 1)) - 1
        if i in sent and i not in first:
            first[i] = t
    return [first[i] - t_sent for i, t_sent in sent.items() if i in first]


def blocks(n: int, size: int) -> list[range]:
    return [range(start, min(n, start + size)) for start in range(0, n, size)]


def encoded(text: str) -> bytes:
    """A masked client text frame, built before the clock starts: a browser frames in native code
    in microseconds, websocket-client in Python takes ~0.1 ms, which is the client's cost, not the
    frame's trip to the robot."""
    import websocket

    return websocket.ABNF.create_frame(text, websocket.ABNF.OPCODE_TEXT).format()


def bench_frames(server: Server, sub: Subscriber, baseline: Baseline | None, n: int, block: int) -> None:
    ws = connect(server.url)
    app, base = [], []
    cpu_s = run_s = 0.0
    for indices in blocks(n, block):
        epoch = ws.heard.epoch
        frames = {i: encoded(frame(value(i, n), epoch=epoch)) for i in indices}
        mark = sub.mark()
        cpu0, t0 = server.cpu_seconds(), time.monotonic()
        times = on_grid(len(indices), RATE_HZ,
                        lambda k, frames=frames, indices=indices: ws.sock.sendall(frames[indices[k]]))
        cpu_s, run_s = cpu_s + server.cpu_seconds() - cpu0, run_s + time.monotonic() - t0
        time.sleep(0.2)
        ws.send(json.dumps({"stop": True}))  # the operator's stop: no deadman, so no new epoch
        app += match_latencies(sub, mark, dict(zip(indices, times, strict=True)), n, MAX_LINEAR)
        if baseline is not None:
            base += baseline.run(indices, n)
    said = ", ".join(f"{k} x{v}" for k, v in sorted(ws.heard.counts.items()))
    print(f"frame -> /cmd_vel at 40 Hz: {summary_ms(app)}  received {len(app)}/{n}  "
          f"server CPU {100 * cpu_s / run_s:.1f}% of one core  RSS {server.rss_mb():.0f} MB"
          + (f"  (the server said: {said})" if said else ""), flush=True)
    if baseline is not None:
        print(f"baseline rclpy -> rclpy:    {summary_ms(base)}  received {len(base)}/{n}  "
              f"(blocks of {block}, alternating with the app's)", flush=True)
        ms = [sorted(x * 1000 for x in lat) for lat in (app, base)]
        print(f"the app's share:            median {statistics.median(ms[0]) - statistics.median(ms[1]):6.3f} ms  "
              f"p99 {percentile(ms[0], 99) - percentile(ms[1], 99):6.3f} ms  (app minus baseline)", flush=True)
    hang_up(ws)


def bench_close(server: Server, sub: Subscriber, trials: int) -> None:
    latencies = []
    for k in range(trials):
        ws = connect(server.url)
        mark = sub.mark()
        fraction = value(k, trials)
        ws.send(frame(fraction))
        sub.wait_for(lambda m: m[1] != 0.0, mark)
        mark = sub.mark()
        t0 = time.monotonic()
        ws.send_close()
        t_zero = sub.wait_for(lambda m: m[1] == 0.0 and m[2] == 0.0, mark)[0]
        latencies.append(t_zero - t0)
        ws.shutdown()
        time.sleep(0.02)
    print(f"close -> zero /cmd_vel:     {summary_ms(latencies)}", flush=True)


def bench_rate(server: Server, sub: Subscriber, hold_s: float) -> None:
    ws = connect(server.url)
    mark = sub.mark()
    on_grid(int(hold_s * 10), 10.0, lambda i: ws.send(frame(0.5)))
    end = sub.mark()
    ws.send(json.dumps({"stop": True}))
    # From the first repeat on: the input itself goes out at once, and the first repeat after it
    # comes 1.2 periods later by design (teleop_control.INPUT_REPEAT_DELAY).
    times = [t for t, lin, _ in sub.since(mark)[: end - mark] if lin == 2.5][1:]
    gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
    period = 1.0 / RATE_HZ
    dev_ms = [abs(g - period) * 1000 for g in gaps]
    rate = (len(times) - 1) / (times[-1] - times[0])
    print(f"held command, repeater at 40 Hz: {rate:.2f} Hz over {times[-1] - times[0]:.1f} s; interval "
          f"mean {statistics.mean(gaps) * 1000:.3f} ms, stdev {statistics.pstdev(gaps) * 1000:.3f} ms, "
          f"|dev| median {statistics.median(dev_ms):.3f} ms p99 {percentile(dev_ms, 99):.3f} ms, "
          f"max interval {max(gaps) * 1000:.2f} ms", flush=True)
    hang_up(ws)


class Baseline:
    """A plain rclpy publisher in this process and its own subscriber process on /bench_baseline."""

    def __init__(self, sub_env: dict):
        import rclpy
        from geometry_msgs.msg import Twist
        from rclpy.context import Context
        from rclpy.signals import SignalHandlerOptions

        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        self._twist = Twist
        self.context = Context()
        rclpy.init(context=self.context, domain_id=int(sub_env["ROS_DOMAIN_ID"]),
                   signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node("bench_baseline_publisher", context=self.context)
        self.pub = self.node.create_publisher(Twist, "/bench_baseline", 10)
        self.sub = Subscriber(sub_env, "/bench_baseline")  # ready once it sees this publisher
        deadline = time.monotonic() + 10
        while self.pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        for _ in range(20):  # warm up discovery both ways
            self.pub.publish(Twist())
            time.sleep(0.02)
        time.sleep(0.3)

    def run(self, indices: range, n: int) -> list[float]:
        """Frames `indices` of `n` at 40 Hz, as the app's were; their latencies."""
        mark = self.sub.mark()

        def send(k: int) -> None:
            msg = self._twist()
            msg.linear.x = value(indices[k], n) * MAX_LINEAR
            self.pub.publish(msg)

        times = on_grid(len(indices), RATE_HZ, send)
        time.sleep(0.2)
        return match_latencies(self.sub, mark, dict(zip(indices, times, strict=True)), n, MAX_LINEAR)

    def close(self) -> None:
        self.sub.stop()
        self.node.destroy_node()
        self.context.try_shutdown()


class OverlayLoad:
    """LiveMap's overlays flowing to `viewers` SSE clients while the teleop figures are taken."""

    def __init__(self, url: str, env: dict, viewers: int):
        self.fleet = SseFleet(url, "/api/events?channels=scan,costmap", viewers)
        self.events = 0
        self.pub = start_peer("overlay_publisher.py", env, "--seconds", "3600")
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()
        print(f"# meanwhile: overlays to {viewers} viewers", flush=True)

    def _count(self, *_args) -> None:
        self.events += 1

    def _read(self) -> None:
        while not self._stop.is_set():
            self.fleet.poll(0.5, self._count)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)
        stop_process(self.pub)
        self.fleet.close()
        print(f"# overlay events received by the viewers: {self.events}", flush=True)


class RecordingLoad:
    """A recording of bench/recording.py's 20 topics, the camera's included, while the teleop figures are taken."""

    def __init__(self, server: Server, env: dict):
        import requests
        from recording import RATES

        self.url = server.url
        self.pub = subprocess.Popen([sys.executable, str(ROOT / "bench" / "recording.py"), "--publish"], cwd=ROOT,
                                    env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        if "publishing" not in self.pub.stdout.readline():
            raise RuntimeError("the recording bench's publisher did not start")
        for topic in RATES:
            wait_for_topic(server, topic, f"{topic} discovered")
        answer = requests.post(self.url + "/api/recordings", json={"topics": list(RATES), "camera": True}, timeout=10)
        answer.raise_for_status()
        self.id = answer.json()["id"]
        print(f"# meanwhile: recording {len(RATES)} topics with the camera", flush=True)

    def stop(self) -> None:
        import requests

        done = requests.post(f"{self.url}/api/recordings/{self.id}/stop", json={}, timeout=30).json()
        self.pub.stdin.close()
        stop_process(self.pub)
        print(f"# recorded {sum(done['counts'].values())} messages in {done['duration_s']:.0f} s, "
              f"dropped {sum(done['dropped'].values())}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=2000)
    parser.add_argument("--block", type=int, default=250, help="frames per block; app and baseline alternate")
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--hold-s", type=float, default=10.0)
    parser.add_argument("--no-baseline", action="store_true")
    parser.add_argument("--overlays", type=int, default=0, metavar="VIEWERS",
                        help="meanwhile, LiveMap's overlay load (bench/overlay_publisher.py: a 1,080-beam scan at "
                             "20 Hz and a 400x400 costmap at 1 Hz) to this many SSE viewers (issue 30)")
    parser.add_argument("--scrape-metrics", type=float, default=0, metavar="S",
                        help="meanwhile, GET /metrics every S seconds, as Prometheus would (issue 42)")
    parser.add_argument("--recording", action="store_true",
                        help="meanwhile, a recording of bench/recording.py's 20 topics with the camera (issue 28)")
    args = parser.parse_args()
    scratch = tempfile.TemporaryDirectory(prefix="rover_web-bench-teleop-")
    # Its own database: the bench must never read or change a real e-stop latch.
    env = ros_env(ROVER_WEB_DB_PATH=os.path.join(scratch.name, "bench.sqlite3"),
                  ROVER_WEB_RECORDINGS_DIR=scratch.name, ROVER_WEB_RECORDING_CAMERA_MAX_HZ="10",
                  ROVER_WEB_RECORDINGS_MIN_FREE_MB="100")
    print(f"# teleop bench on {machine()}: app in its own process, subscriber in another "
          f"(ROS domain {env['ROS_DOMAIN_ID']})", flush=True)
    server = Server(env)
    sub = baseline = load = scraper = None
    try:
        if args.scrape_metrics:
            scraper = Scraper(server.url, args.scrape_metrics)
        if args.overlays:
            load = OverlayLoad(server.url, env, args.overlays)
        elif args.recording:
            load = RecordingLoad(server, env)
        sub = Subscriber(env)
        deadline = time.monotonic() + 10
        import requests
        while not sub.messages:  # discovery: publish zeros until the subscriber hears one
            if time.monotonic() > deadline:
                raise RuntimeError("the subscriber never heard the app")
            requests.post(server.url + "/api/teleop", json={"command": "stop"}, timeout=5)
            time.sleep(0.05)
        baseline = None if args.no_baseline else Baseline(env)
        bench_frames(server, sub, baseline, args.frames, args.block)
        bench_close(server, sub, args.trials)
        bench_rate(server, sub, args.hold_s)
    finally:
        if scraper:
            print(scraper.stop(), flush=True)
        if load:
            load.stop()
        if baseline:
            baseline.close()
        if sub:
            sub.stop()
        server.stop()
    scratch.cleanup()


if __name__ == "__main__":
    main()
