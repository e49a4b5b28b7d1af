"""The Broadcaster over real socket pairs: each client gets exactly its channels' frames, in order,
from the thread that changed the hub; a client whose socket is full skips to the newest values
and gets every ring event it missed."""

import re
import socket
import time

import pytest

from rover_web.events.broadcast import Broadcaster
from rover_web.events.hub import EventHub

SOCKETS = []


@pytest.fixture
def hub():
    hub = EventHub()
    hub.register("odom", "status", "log")
    yield hub
    hub.close()
    time.sleep(0.1)  # the broadcaster's thread ends with the hub and shuts its sockets down
    while SOCKETS:
        SOCKETS.pop().close()


def attach(hub, broadcaster, channels, sndbuf=None):
    ours, theirs = socket.socketpair()
    SOCKETS.extend((ours, theirs))
    if sndbuf:
        ours.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, sndbuf)
    sub = hub.subscribe(channels)
    sub.snapshot()
    broadcaster.attach(ours, sub)
    theirs.settimeout(2)
    return ours, theirs


def read_events(sock, until=None, timeout=2.0):
    """(event, data) pairs until `until` is seen (or the socket stays quiet for 0.2 s)."""
    buf, deadline = b"", time.monotonic() + timeout
    sock.settimeout(0.2)
    while time.monotonic() < deadline:
        try:
            chunk = sock.recv(65536)
        except TimeoutError:
            if until is None:
                break
            continue
        buf += chunk
        if until is not None and until.encode() in buf:
            break
    return re.findall(r"event: (\w+)\ndata: (.*)\n\n", buf.decode())


def test_each_client_gets_its_own_channels_in_order(hub):
    broadcaster = Broadcaster(hub, keepalive_s=30)
    _, odom_only = attach(hub, broadcaster, ["odom"])
    _, status_only = attach(hub, broadcaster, ["status"])
    _, both = attach(hub, broadcaster, ["odom", "status"])
    time.sleep(0.2)  # the broadcaster's thread has taken them in
    for i in range(20):
        hub.publish("odom", {"i": i})
        if i % 5 == 4:
            hub.publish("status", {"i": i})
    hub.emit("log", {"end": True})
    assert read_events(odom_only, until='{"i":19}') == [("odom", f'{{"i":{i}}}') for i in range(20)]
    assert read_events(status_only, until='{"i":19}') == [("status", f'{{"i":{i}}}') for i in (4, 9, 14, 19)]
    got = read_events(both, until='{"i":19}', timeout=2) + read_events(both)
    assert [e for e in got if e[0] == "odom"] == [("odom", f'{{"i":{i}}}') for i in range(20)]
    assert [e for e in got if e[0] == "status"] == [("status", f'{{"i":{i}}}') for i in (4, 9, 14, 19)]


def test_a_full_socket_skips_to_the_newest_values_and_keeps_every_ring_event(hub):
    broadcaster = Broadcaster(hub, keepalive_s=30)
    _, slow = attach(hub, broadcaster, ["odom", "log"], sndbuf=4096)
    time.sleep(0.2)
    big = "x" * 2000
    for i in range(200):  # far more than the slow socket holds while nobody reads it
        hub.publish("odom", {"i": i, "pad": big})
        if i % 50 == 0:
            hub.emit("log", {"n": i})
    hub.publish("odom", {"i": "last"})
    slow_got = read_events(slow, until='"last"', timeout=5)
    odom = [d for e, d in slow_got if e == "odom"]
    assert len(odom) < 200 and odom[-1] == '{"i":"last"}'  # stale values skipped, the newest arrived
    assert [d for e, d in slow_got if e == "log"] == [f'{{"n":{n}}}' for n in (0, 50, 100, 150)]
    indices = [int(re.search(r'"i":(\d+)', d).group(1)) for d in odom[:-1]]
    assert indices == sorted(indices)  # never out of order
