"""A browser behind a slow link gets the newest value, not a backlog: the server's send buffer for
an event stream stays small, so the Broadcaster's "full socket, skip to the newest" rule starts
before old events pile up. Through a 2 Mbit/s link an odometry value was 3 s old at the median
and 14 s at worst before (bench/link.py, issue 25): the kernel had grown the buffer to megabytes."""

import socket
import threading
import time

from tests.integration.camera.throttle import Throttle, server_queue

PAD = "x" * 900  # about 1 kB an event
LINK_BPS = 50_000


def test_a_viewer_behind_a_slow_link_holds_a_small_backlog_and_gets_the_newest_value(live_server):
    link = Throttle(live_server.port, LINK_BPS, rcvbuf=65536, chunk=4096)
    sock = socket.create_connection(("127.0.0.1", link.port))
    received = bytearray()
    done = threading.Event()

    def read():
        try:
            while data := sock.recv(65536):
                received.extend(data)
        except OSError:
            pass
        done.set()

    try:
        sock.sendall(b"GET /api/events?channels=odom HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: text/event-stream\r\n\r\n")
        threading.Thread(target=read, daemon=True).start()
        deadline = time.monotonic() + 10
        while link.upstream_port is None or b"\r\n\r\n" not in received:
            assert time.monotonic() < deadline, "the stream did not start"
            time.sleep(0.01)
        hub = live_server.rover.hub
        queued = []
        for i in range(2000):  # 2 MB in about 4 s: forty times what the link carries
            hub.publish("odom", {"seq": i, "pad": PAD})
            if i % 20 == 0:
                queued.append(server_queue(live_server.port, link.upstream_port) or 0)
                time.sleep(0.04)
        t_newest = time.monotonic()
        hub.publish("odom", {"seq": "newest", "pad": ""})
        while b'"seq":"newest"' not in received:
            assert time.monotonic() < t_newest + 60, "the newest value never arrived"
            time.sleep(0.02)
        waited = time.monotonic() - t_newest
        # What the server kept is what the link still had to carry before the newest value: a
        # bound in bytes, not a timing (the wait is in the message to show what it means).
        assert max(queued) < 100_000, f"the server kept up to {max(queued)} bytes; the newest value took {waited:.1f} s"
    finally:
        sock.close()
        link.close()
