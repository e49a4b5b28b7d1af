"""`flask run` leaves no epoll descriptor behind when clients reset their connections (issue 27).

Werkzeug's request handler drains each socket through a fresh selector after the response; when
the client's TCP reset makes that read raise, the selector is not closed, and being a reference
cycle it held its epoll descriptor until a garbage collection, which an idle server may not run
for a long time. rover_web/web/dev_server.py gives the handler a selector without the cycle.
"""

import gc
import os
import socket
import subprocess
import sys

import psutil
import pytest

from tests.support.storm import PROBE, cut
from tests.support.waiting import wait_until

EPOLL = "anon_inode:[eventpoll]"


def epolls(pid: int) -> int:
    count = 0
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            count += os.readlink(f"/proc/{pid}/fd/{fd}") == EPOLL
        except OSError:
            pass  # closed meanwhile
    return count


def reset_storm(port: int, opens: int) -> None:
    """SSE opens cut by a TCP reset: a third before the answer, a third just after its first bytes
    (while the server drains the socket), the rest after a moment, as in the black-box run. With
    the default cap (64 streams) many are 503s, each also drained."""
    held = []
    for i in range(opens):
        sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        sock.sendall(f"GET /api/events?channels=status,odom HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                     f"Accept: text/event-stream\r\n\r\n".encode())
        if i % 3 == 0:
            cut(sock)
            continue
        try:
            sock.recv(64)
        except OSError:
            pass
        if i % 3 == 1:
            cut(sock)
        else:
            held.append(sock)
    for sock in held:
        cut(sock)


def test_no_descriptor_waits_for_the_garbage_collector(live_server_factory):
    """The mechanism, in this process with the collector off: Werkzeug's own server (what `flask
    run` serves with) gives every descriptor back without a collection. A small cap, so most
    opens are 503s that the client resets while the server drains them."""
    live_server = live_server_factory(ROVER_WEB_MAX_STREAMS=8)
    pid = os.getpid()
    reset_storm(live_server.port, 6)  # the SSE broadcaster's one selector, for as long as the server runs
    gc.collect()
    baseline = epolls(pid)
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        reset_storm(live_server.port, 90)
        wait_until(lambda: epolls(pid) <= baseline, 10, f"epoll descriptors back to {baseline} without a gc")
    finally:
        if was_enabled:
            gc.enable()


@pytest.mark.ros
def test_under_flask_run_a_reset_storm_leaves_no_descriptor_or_thread(server_process):
    """The black-box run: `flask run`, 200 SSE opens cut by resets while e-stop requests run."""
    server = server_process().start()
    proc = psutil.Process(server.proc.pid)
    reset_storm(server.port, 20)  # warm-up: first-use imports and caches
    baseline = {"epoll": epolls(proc.pid), "threads": proc.num_threads()}
    prober = subprocess.Popen([sys.executable, "-c", PROBE, str(server.port)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert prober.stdout.readline().strip() == "probing"
        reset_storm(server.port, 200)
    finally:
        prober.communicate("stop\n", timeout=30)

    def settled() -> bool:
        return epolls(proc.pid) <= baseline["epoll"] and proc.num_threads() <= baseline["threads"] + 2
    wait_until(settled, 10, f"descriptors and threads back to {baseline}")
