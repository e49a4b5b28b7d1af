"""Should the SSE event stream be compressed? Bytes saved against CPU, per viewer, at 1 and 50 viewers.

    .venv/bin/python bench/sse_compression.py [--seconds 5] [--viewers 1 50]

The frames are the app's own (rover_web.events.hub.sse_frame of rover_web.telemetry's odom summary,
the busiest channel at 100 Hz, plus the 1 Hz status heartbeat), made from a moving robot. Today the
Broadcaster frames an event once and writes the same bytes to every viewer. A compressed stream has
state per viewer (each starts at a different event, and every event must be flushed at once, or it
would wait in the compressor), so each event is compressed once per viewer: deflate (gzip) with a
sync flush, and brotli with a flush, as a browser's `Content-Encoding` would need. Printed: the bytes
per event plain and compressed, and the CPU each costs per event per viewer and for all viewers, next
to what the event path costs today (figures from bench/events.py in BENCHMARKS.md). One JSON line last.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import zlib

import brotli
from common import ROOT, machine

sys.path.insert(0, str(ROOT))
from rover_web.events.hub import encode, sse_frame  # noqa: E402


def frames(count: int) -> list[bytes]:
    out = []
    for i in range(count):
        t = 1_795_000_000 + i / 100
        yaw = 0.3 * math.sin(i / 200)
        # The fields and rounding of rover_web/telemetry/msgs.py's summary.
        odom = {"x": round(3.0 * math.cos(i / 300), 3), "y": round(2.0 * math.sin(i / 300), 3),
                "yaw": round(yaw, 4), "linear": round(0.5 + 0.1 * math.sin(i / 50), 3),
                "angular": round(0.1 * math.cos(i / 70), 3), "frame_id": "odom", "stamp": t}
        out.append(sse_frame(i, "odom", encode(odom)))
        if i % 100 == 0:
            status = {"uptime_s": i / 100, "topics": [{"topic": "/odom", "age_s": 0.01, "rate_hz": 100.0},
                                                       {"topic": "/fix", "age_s": 0.2, "rate_hz": 5.0}],
                      "clients": 1, "callback_errors": 0}
            out.append(sse_frame(i, "status", encode(status)))
    return out


def cost(make, events: list[bytes], viewers: int) -> tuple[int, float]:
    """(compressed bytes for one viewer, CPU seconds for all viewers) over the events."""
    streams = [make() for _ in range(viewers)]
    sent = 0
    start = time.process_time()
    for frame in events:
        for n, stream in enumerate(streams):
            out = stream(frame)
            if n == 0:
                sent += len(out)
    return sent, time.process_time() - start


def deflate():
    c = zlib.compressobj(6, zlib.DEFLATED, 31)  # gzip framing, as Content-Encoding: gzip
    return lambda frame: c.compress(frame) + c.flush(zlib.Z_SYNC_FLUSH)


def brotli_stream(quality: int):
    def make():
        c = brotli.Compressor(quality=quality)
        return lambda frame: c.process(frame) + c.flush()
    return make


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="of events at 100 Hz")
    parser.add_argument("--viewers", type=int, nargs="*", default=[1, 50])
    args = parser.parse_args()
    events = frames(int(args.seconds * 100))
    plain = sum(len(f) for f in events)
    print(f"# SSE compression on {machine()}: {len(events)} events ({args.seconds:g} s of odom at 100 Hz + status), "
          f"{plain / len(events):.0f} B per event plain", flush=True)
    result = {"bench": "sse_compression", "events": len(events), "plain_bytes_per_event": round(plain / len(events), 1),
              "machine": machine(), "codecs": {}}
    for name, make in (("gzip", deflate), ("br-4", brotli_stream(4)), ("br-1", brotli_stream(1))):
        result["codecs"][name] = {}
        for viewers in args.viewers:
            sent, cpu = cost(make, events, viewers)
            per_event_us = cpu / len(events) / viewers * 1e6
            figures = {"bytes_per_event": round(sent / len(events), 1), "saved": round(1 - sent / plain, 3),
                       "cpu_us_per_event_per_viewer": round(per_event_us, 2),
                       "cpu_share_at_100hz": round(cpu / len(events) * 100, 4)}
            result["codecs"][name][str(viewers)] = figures
            print(f"{name:5s} {viewers:3d} viewers: {figures['bytes_per_event']:6.1f} B per event "
                  f"({figures['saved'] * 100:.0f} % saved), {per_event_us:6.1f} µs CPU per event per viewer, "
                  f"{figures['cpu_share_at_100hz'] * 100:.1f} % of a core at 100 Hz for all", flush=True)
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
