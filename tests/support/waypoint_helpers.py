"""Helpers for the waypoints tests and bench: a local tile server, warm-up, reading the database."""

from __future__ import annotations

import io
import sqlite3
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import requests

FLOAT64_MULTI_ARRAY = "std_msgs/msg/Float64MultiArray"
WARM_UP_LABEL = "warm-up"


def tile_png(z: int, x: int, y: int) -> bytes:
    """A 256 px tile of one magenta-ish colour that differs per tile (so a y-flip would show)."""
    from PIL import Image

    colour = (255, (x * 37 + y * 11 + z * 5) % 64, 255)
    buf = io.BytesIO()
    Image.new("RGB", (256, 256), colour).save(buf, "PNG")
    return buf.getvalue()


class TileServer:
    """http://127.0.0.1:<port>/{z}/{x}/{y}.png, like a real XYZ tile server; 404 beyond max_zoom."""

    def __init__(self, max_zoom: int = 18):
        self.requests: list[str] = []
        self.served: dict[tuple[int, int, int], bytes] = {}
        outer = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self):  # noqa: N802 - http.server's naming
                outer.requests.append(self.path)
                try:
                    z, x, rest = self.path.strip("/").split("/")
                    z, x, y = int(z), int(x), int(rest.removesuffix(".png"))
                except ValueError:
                    self.send_error(400)
                    return
                if z > max_zoom:
                    self.send_error(404)
                    return
                body = outer.served.setdefault((z, x, y), tile_png(z, x, y))
                self.send_response(200)
                self.send_header("Content-Type", "image/png")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, *args):
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_port}"
        self.template = self.url + "/{z}/{x}/{y}.png"
        self._thread = threading.Thread(target=self.server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self.server.shutdown()
        self.server.server_close()
        self._thread.join(2)


def warm_up_topic(base_url: str, peer, topic: str = "/waypoints", timeout: float = 15.0) -> None:
    """Discovery matches both ends a moment apart: add throw-away waypoints until the subscriber hears
    one, then delete them, so the test's own messages cannot be lost to discovery."""
    deadline = time.monotonic() + timeout
    while not peer.received(topic):
        assert time.monotonic() < deadline, f"the subscriber never heard the app on {topic}"
        requests.post(base_url + "/api/waypoints", json={"lng": 0.5, "lat": 0.5, "label": WARM_UP_LABEL}, timeout=5)
        time.sleep(0.1)
    requests.delete(base_url + "/api/waypoints", timeout=5).raise_for_status()
    time.sleep(0.2)  # a warm-up message still in flight lands before the clear below
    peer.clear(topic)


def stored_rows(db_path) -> list[tuple]:
    """(position, lng, lat, label) of every stored waypoint, read by a fresh connection."""
    conn = sqlite3.connect(db_path)
    try:
        return conn.execute("SELECT position, lng, lat, label FROM waypoints ORDER BY position").fetchall()
    finally:
        conn.close()
