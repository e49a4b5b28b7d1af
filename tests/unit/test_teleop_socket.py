"""TeleopSocket's threading contract, with a stand-in for simple_websocket's connection object.

The test plays simple_websocket's reader thread: it appends messages to `input_buffer` and calls
`event.set()`, exactly as `Base._handle_events` does. The real library, a real socket and a real
ROS subscriber are covered by tests/integration/test_teleop_*.py.
"""

import json
import threading

import pytest

from rover_web.teleop_control import Limits, TeleopController
from rover_web.teleop_socket import CLOSE_INTERNAL_ERROR, InlineFrames, TeleopSocket


class Output:
    def __init__(self):
        self.sent = []

    def send(self, linear, angular):
        self.sent.append((linear, angular))

    def zero(self):
        self.sent.append((0.0, 0.0))


class Socket:
    def __init__(self):
        self.shut_down = False

    def shutdown(self, how):
        self.shut_down = True


class Connection:
    """The attributes of simple_websocket.Server that TeleopSocket uses (no reader thread: the
    test is the reader)."""

    def __init__(self):
        self.sock = Socket()
        self.thread = None
        self.event = InlineFrames()
        self.input_buffer = []
        self.connected = True
        self.sent = []
        self.closed_with = None
        self._cond = threading.Condition()

    def send(self, text):
        with self._cond:
            self.sent.append(json.loads(text))
            self._cond.notify_all()

    def close(self, reason=None, message=None):
        self.closed_with = (reason, message)
        self.connected = False

    def arrive(self, *frames):
        """What the reader thread does for each complete message."""
        for frame in frames:
            self.input_buffer.append(frame if isinstance(frame, str) else json.dumps(frame))
            self.event.set()

    def wait_sent(self, predicate, timeout=5.0):
        with self._cond:
            assert self._cond.wait_for(lambda: any(predicate(m) for m in self.sent), timeout), self.sent


@pytest.fixture
def rig():
    out = Output()
    controller = TeleopController(out, Limits(5.0, 2.0), rate_hz=40, deadman_s=0.3)
    ws = Connection()
    session = controller.connect("alice")
    sock = TeleopSocket(ws, controller, session, max_frame_bytes=4096)
    stopping = threading.Event()
    thread = threading.Thread(target=sock.serve, args=({"type": "hello"}, stopping), daemon=True)
    yield out, controller, ws, sock, stopping, thread
    stopping.set()
    ws.event.wake()
    thread.join(5)
    assert not thread.is_alive()


def test_frames_before_attach_run_at_attach_then_each_runs_in_the_reader_thread(rig):
    out, controller, ws, sock, stopping, thread = rig
    ws.arrive({"linear": 0.2, "angular": 0.0})  # before serve() attaches: buffered, not handled
    assert out.sent == []
    thread.start()
    ws.wait_sent(lambda m: m["type"] == "hello")
    ws.wait_sent(lambda m: m.get("in_control") is True)
    assert out.sent == [(1.0, 0.0)]
    ws.arrive({"linear": -0.4, "angular": 0.5})
    assert out.sent[-1] == (-2.0, 1.0)  # published before the reader's set() returned


def test_a_state_change_wakes_the_socket_thread_at_once(rig, monkeypatch):
    out, controller, ws, sock, stopping, thread = rig
    monkeypatch.setattr("rover_web.teleop_socket.POLL_S", 600.0)  # only a wake-up can deliver it
    thread.start()
    ws.arrive({"linear": 0.2, "angular": 0.0})
    ws.wait_sent(lambda m: m.get("in_control") is True)
    other = controller.connect("bob")
    controller.takeover(other)
    ws.wait_sent(lambda m: m.get("reason") == "taken_over")
    controller.disconnect(other)


def test_invalid_payload_stops_the_robot_then_closes_and_ignores_the_rest(rig):
    out, controller, ws, sock, stopping, thread = rig
    thread.start()
    ws.arrive({"linear": 0.5, "angular": 0.0})
    ws.arrive("{not json", {"linear": 1.0, "angular": 0.0})
    thread.join(5)
    assert ws.closed_with[0] == 1007
    assert ws.sock.shut_down  # no reader to answer the close: the connection is cut
    assert out.sent == [(2.5, 0.0), (0.0, 0.0)]  # the zero came before the close; the later frame never ran
    assert controller.state()["holder"] is None


def test_an_unexpected_error_closes_with_1011_and_never_escapes_into_the_reader(rig, monkeypatch):
    out, controller, ws, sock, stopping, thread = rig
    thread.start()
    ws.arrive({"linear": 0.5, "angular": 0.0})

    def broken(*args, **kwargs):
        raise RuntimeError("a bug")

    monkeypatch.setattr(controller, "drive", broken)
    ws.arrive({"linear": 0.7, "angular": 0.0})  # must not raise here: that would end the reader thread
    thread.join(5)
    assert ws.closed_with[0] == CLOSE_INTERNAL_ERROR
    assert out.sent[-1] == (0.0, 0.0)
    assert controller.state()["holder"] is None


def test_connection_lost_frees_control_from_the_reader_thread(rig):
    out, controller, ws, sock, stopping, thread = rig
    thread.start()
    ws.arrive({"linear": 0.5, "angular": 0.0})
    ws.wait_sent(lambda m: m.get("in_control") is True)
    ws.connected = False
    ws.event.set()  # the reader thread's last act when the peer goes away
    assert out.sent[-1] == (0.0, 0.0)  # zero before set() returned, not when the socket thread wakes
    assert controller.state()["holder"] is None
    thread.join(5)
    assert not thread.is_alive()
