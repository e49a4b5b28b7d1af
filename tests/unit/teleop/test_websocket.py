"""TeleopSocket and its FrameReader over a real socket pair: the test is the browser, writing
masked frames and reading what the server sends. No HTTP server and no ROS here; the route,
the handshake and a real /cmd_vel subscriber are in tests/integration/test_teleop_*.py."""

import json
import socket
import struct
import threading

import pytest

from rover_web.teleop.commands import Limits
from rover_web.teleop.control import TeleopController
from rover_web.teleop.websocket import CLOSE_INTERNAL_ERROR, CLOSE_POLICY_VIOLATION, FrameReader, TeleopSocket
from rover_web.teleop.ws_frames import OP_CLOSE, OP_PING, OP_PONG, OP_TEXT
from tests.support import ws_wire


class Output:
    """CmdVelOutput's interface; records each Twist and the thread that published it."""

    def __init__(self):
        self.sent = []
        self.threads = []

    def send(self, linear, angular):
        self.sent.append((linear, angular))
        self.threads.append(threading.current_thread())

    def zero(self):
        self.send(0.0, 0.0)


class Connection:
    """What simple_websocket.Server is after its handshake, as far as TeleopSocket goes: a socket,
    `connected`, and the reader thread it built from `thread_class` and started."""

    def __init__(self, sock):
        self.sock = sock
        self.connected = True
        self.thread = FrameReader(target=self._thread)
        self.thread.start()

    def _thread(self):  # the library's own loop, which FrameReader replaces
        raise AssertionError("simple_websocket's reader must not run")


class Browser:
    def __init__(self, sock):
        self.sock = sock
        sock.settimeout(5)

    def send(self, *messages):
        self.sock.sendall(b"".join(ws_wire.text(m) for m in messages))

    def next(self, opcode=OP_TEXT):
        """The next frame with `opcode`, skipping others; JSON for text, (code, reason) for close."""
        while True:
            op, payload = ws_wire.read_frame(self.sock)
            if op != opcode:
                continue
            if op == OP_TEXT:
                return json.loads(payload)
            if op == OP_CLOSE:
                return struct.unpack("!H", payload[:2])[0], payload[2:].decode()
            return payload

    def answer_close(self, code):
        """What a browser does with the server's close frame: answer it, then see the stream end
        and close its side."""
        self.sock.sendall(ws_wire.close(code))
        assert self.at_eof()
        self.sock.shutdown(socket.SHUT_WR)

    def wait_for(self, predicate):
        while not predicate(message := self.next()):
            pass
        return message

    def at_eof(self) -> bool:
        try:
            return self.sock.recv(4096) == b""
        except ConnectionResetError:
            return True


@pytest.fixture
def rig():
    out = Output()
    controller = TeleopController(out, Limits(5.0, 2.0), rate_hz=40, deadman_s=0.3)
    server_end, browser_end = socket.socketpair()
    ws = Connection(server_end)
    session = controller.connect("alice")
    teleop = TeleopSocket(ws, controller, session, max_frame_bytes=4096)
    stopping = threading.Event()
    serve = threading.Thread(target=teleop.serve, args=({"type": "hello"}, stopping),
                             kwargs={"ping_s": None, "link_s": None}, daemon=True)
    yield out, controller, ws, Browser(browser_end), stopping, serve
    stopping.set()
    session.wake()  # a test may have stretched the request thread's poll
    if serve.is_alive():
        serve.join(5)
    assert not serve.is_alive() and not ws.thread.is_alive()
    server_end.close()
    browser_end.close()


def start(serve, browser):
    serve.start()
    assert browser.next()["type"] == "hello"


def test_frames_sent_before_attach_wait_then_each_is_published_from_the_reader_thread(rig):
    out, controller, ws, browser, stopping, serve = rig
    browser.send({"linear": 0.2, "angular": 0.0})  # before serve(): it waits in the socket
    assert not ws.thread._attached.wait(0.1) and out.sent == []
    start(serve, browser)
    browser.wait_for(lambda m: m.get("in_control") is True)
    browser.send({"linear": -0.4, "angular": 0.5})
    browser.sock.sendall(ws_wire.close(1000))
    assert browser.next(OP_CLOSE)[0] == 1000  # the close answered with its own code
    serve.join(5)
    assert out.sent == [(1.0, 0.0), (-2.0, 1.0), (0.0, 0.0)]
    assert set(out.threads) == {ws.thread}
    assert controller.state()["holder"] is None


def test_a_state_change_wakes_the_request_thread_at_once(rig, monkeypatch):
    out, controller, ws, browser, stopping, serve = rig
    monkeypatch.setattr("rover_web.teleop.websocket.POLL_S", 600.0)  # only a wake-up can deliver it
    start(serve, browser)
    browser.send({"linear": 0.2, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)
    other = controller.connect("bob")
    controller.takeover(other)
    browser.wait_for(lambda m: m.get("reason") == "taken_over")
    controller.disconnect(other)


def test_an_error_frame_answers_a_bad_value_and_the_socket_stays_open(rig):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send('{"linear": NaN, "angular": 0}')
    assert browser.next()["error"] == "non_finite"
    browser.send({"linear": 0.1, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)
    assert out.sent == [(0.5, 0.0)]


def test_seq_and_t_reach_the_controller_and_a_late_or_malformed_one_gets_an_error_frame(rig):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send({"linear": 0.2, "angular": 0.0, "seq": 5, "t": 1000.5})
    browser.wait_for(lambda m: m.get("in_control") is True)
    browser.send({"linear": 0.6, "angular": 0.0, "seq": 4, "t": 990.0})
    assert browser.next()["error"] == "stale_seq"
    for bad in ({"seq": -1}, {"seq": 1.5}, {"seq": None}, {"seq": "6"}, {"t": "now"}, {"t": -1}, {"t": None}):
        browser.send({"linear": 0.6, "angular": 0.0, **bad})
        assert browser.next()["error"] in ("bad_type", "out_of_range"), bad
    assert out.sent == [(1.0, 0.0)] + [(0.0, 0.0)]  # the first bad frame stopped it; nothing else moved


def test_a_socket_gets_measuring_pings_and_periodic_state_frames_with_its_link():
    out = Output()
    controller = TeleopController(out, Limits(5.0, 2.0), rate_hz=40, deadman_s=0.3)
    server_end, browser_end = socket.socketpair()
    ws = Connection(server_end)
    teleop = TeleopSocket(ws, controller, controller.connect("alice"), max_frame_bytes=4096)
    stopping = threading.Event()
    serve = threading.Thread(target=teleop.serve, args=({"type": "hello"}, stopping),
                             kwargs={"ping_s": None, "link_s": 0.05}, daemon=True)
    serve.start()
    browser = Browser(browser_end)
    try:
        ping = browser.next(OP_PING)
        assert len(ping) == 4  # an id, answered like any browser does: the same payload back
        browser.sock.sendall(ws_wire.masked(0x8A, ping))
        state = browser.wait_for(lambda m: m.get("reason") == "link" and m["link"]["rtt_ms"] is not None)
        assert state["type"] == "state" and state["link"]["quality"] == "ok" and state["link"]["rtt_ms"] >= 0
        assert {"jitter_ms", "stalls", "last_stall_ms"} <= set(state["link"])
    finally:
        stopping.set()
        serve.join(5)
        server_end.close()
        browser_end.close()
    assert not serve.is_alive()


def test_pings_are_answered_with_their_payload_by_the_reader(rig):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.sock.sendall(ws_wire.masked(0x89, b"are you there"))
    assert browser.next(OP_PONG) == b"are you there"


def test_invalid_json_stops_the_robot_then_closes_1007_and_cuts_a_client_that_never_answers(rig):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send({"linear": 0.5, "angular": 0.0})
    browser.send("{not json", {"linear": 1.0, "angular": 0.0})
    assert browser.next(OP_CLOSE)[0] == 1007
    serve.join(5)  # the browser never answers the close: cut after the grace time
    assert browser.at_eof()
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)]  # the frame after the bad one never ran
    assert controller.state()["holder"] is None


@pytest.mark.parametrize("frame, code", [
    (ws_wire.masked(0x81, b'{"linear": 1, "angular": 0}', mask_bit=False), 1002),  # unmasked
    (ws_wire.masked(0xC1, b'{"linear": 1, "angular": 0}'), 1002),                  # compressed: none agreed
    (ws_wire.masked(0x81, b"x" * 5000), 1009),
    (ws_wire.masked(0x81, b"\xff"), 1007),
    (ws_wire.masked(0x82, b"\x01\x02"), 1003),                                     # binary
])
def test_a_broken_frame_stops_the_robot_and_closes_with_its_code(rig, frame, code):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send({"linear": 0.5, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)
    browser.sock.sendall(frame)
    assert browser.next(OP_CLOSE)[0] == code
    browser.answer_close(code)  # as a browser does: the connection ends without waiting out the grace
    serve.join(1.0)
    assert not serve.is_alive()
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)]


def test_an_unexpected_error_closes_1011_and_still_stops_the_robot(rig, monkeypatch):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send({"linear": 0.5, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)

    def broken(*args, **kwargs):
        raise RuntimeError("a bug")

    monkeypatch.setattr(controller, "drive", broken)
    browser.send({"linear": 0.7, "angular": 0.0})
    assert browser.next(OP_CLOSE)[0] == CLOSE_INTERNAL_ERROR
    browser.answer_close(CLOSE_INTERNAL_ERROR)
    serve.join(1.0)
    assert not serve.is_alive()
    assert out.sent[-1] == (0.0, 0.0)
    assert controller.state()["holder"] is None


def test_a_lost_connection_is_stopped_by_the_reader_that_saw_it(rig, monkeypatch):
    out, controller, ws, browser, stopping, serve = rig
    monkeypatch.setattr("rover_web.teleop.websocket.POLL_S", 600.0)  # the request thread will not look
    start(serve, browser)
    browser.send({"linear": 0.5, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)
    browser.sock.shutdown(socket.SHUT_RDWR)  # gone, without a close frame
    serve.join(5)
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)]
    assert out.threads[-1] is ws.thread
    assert not ws.connected  # flask-sock's own close() will do nothing


def test_shutdown_closes_1001_after_the_robot_is_stopped(rig):
    out, controller, ws, browser, stopping, serve = rig
    start(serve, browser)
    browser.send({"linear": 0.5, "angular": 0.0})
    browser.wait_for(lambda m: m.get("in_control") is True)
    stopping.set()
    assert browser.next(OP_CLOSE)[0] == 1001
    browser.answer_close(1001)
    serve.join(1.0)
    assert not serve.is_alive()
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)]


def test_a_client_that_misses_a_ping_loses_the_socket_and_control():
    out = Output()
    controller = TeleopController(out, Limits(5.0, 2.0), rate_hz=40, deadman_s=10.0)
    server_end, browser_end = socket.socketpair()
    ws = Connection(server_end)
    teleop = TeleopSocket(ws, controller, controller.connect("mute"), max_frame_bytes=4096)
    serve = threading.Thread(target=teleop.serve, args=({"type": "hello"}, threading.Event(), 0.1, None), daemon=True)
    serve.start()
    browser = Browser(browser_end)
    browser.next()
    browser.send({"linear": 0.5, "angular": 0.0})
    ping = browser.next(OP_PING)
    browser.sock.sendall(ws_wire.masked(0x8A, ping))  # answers the first ping...
    browser.next(OP_PING)                             # ...not the second
    assert browser.next(OP_CLOSE)[0] == CLOSE_POLICY_VIOLATION
    serve.join(5)
    assert not serve.is_alive() and not ws.thread.is_alive()
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)] and controller.state()["holder"] is None
    server_end.close()
    browser_end.close()


def test_a_reader_never_attached_ends_when_released():
    server_end, browser_end = socket.socketpair()
    ws = Connection(server_end)
    ws.thread.attach(None)
    ws.thread.join(5)
    assert not ws.thread.is_alive()
    server_end.close()
    browser_end.close()


def test_the_reader_refuses_to_stand_in_for_anything_but_a_connection_loop():
    with pytest.raises(TypeError):
        FrameReader(target=print)
