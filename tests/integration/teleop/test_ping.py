"""WebSocket pings: a client that answers keeps its socket and control; one that does not loses both."""

import struct
import time

import requests
import websocket

from rover_web.teleop.ws_frames import OP_CLOSE
from tests.support import ws_wire
from tests.support.teleop_support import TeleopClient

PING_S = 0.3


def close_codes(sock) -> list[int]:
    """Close codes among the server's frames, read until the connection ends."""
    codes = []
    while True:
        try:
            opcode, payload = ws_wire.read_frame(sock)
        except EOFError:
            return codes
        if opcode == OP_CLOSE:
            codes.append(struct.unpack("!H", payload[:2])[0])


def holder(url):
    return requests.get(url + "/api/teleop", timeout=5).json()["holder"]


def test_a_client_that_answers_pings_keeps_control_while_idle(live_server_factory):
    server = live_server_factory(ROVER_WEB_TELEOP_WS_PING_S=PING_S)
    client = TeleopClient(server.url, name="alice")  # websocket-client answers pings while it reads
    client.drive(0.1)
    client.wait_for(lambda m: m.get("in_control") is True)
    client.send({"stop": True})
    time.sleep(6 * PING_S)
    assert not client.closed.is_set()
    assert holder(server.url)["name"] == "alice"
    client.close()


def test_a_client_that_stops_answering_pings_loses_the_socket_and_control(live_server_factory):
    server = live_server_factory(ROVER_WEB_TELEOP_WS_PING_S=PING_S)
    url = server.url.replace("http://", "ws://", 1) + "/ws/teleop?name=mute"
    mute = websocket.create_connection(url, timeout=10)
    try:
        assert '"hello"' in mute.recv()
        mute.send('{"linear": 0.1, "angular": 0.0}')
        deadline = time.monotonic() + 5
        while (h := holder(server.url)) is None or h["name"] != "mute":
            assert time.monotonic() < deadline, "the mute client never took control"
            time.sleep(0.02)
        # From now on it never reads, so it never answers a ping.
        deadline = time.monotonic() + 10 * PING_S
        while holder(server.url) is not None:
            assert time.monotonic() < deadline, "control was not freed after missed pings"
            time.sleep(0.05)
        # It never answers the close either (a raw read, so websocket-client cannot answer for
        # it): the server cuts the connection rather than keep a thread and a socket for it.
        mute.sock.settimeout(5)
        assert close_codes(mute.sock) == [1008]
    finally:
        mute.close()
