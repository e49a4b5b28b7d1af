"""The data channel glue with a real TeleopController and a fake channel: hello, frames judged by
handle_frame off the loop, replies and state frames sent back, close zeroes at once."""

import json
from concurrent.futures import ThreadPoolExecutor

import pytest

from rover_web.teleop.control import Limits, TeleopController
from rover_web.teleop.datachannel import TeleopChannel


class Channel:
    def __init__(self):
        self.sent, self.readyState, self.closed = [], "open", False

    def send(self, text):
        assert self.readyState == "open"
        self.sent.append(json.loads(text))

    def close(self):
        self.closed, self.readyState = True, "closed"


class Output:
    def __init__(self):
        self.sent = []

    def send(self, linear, angular):
        self.sent.append((linear, angular))

    def zero(self):
        self.sent.append((0.0, 0.0))


@pytest.fixture
def rig():
    out = Output()
    controller = TeleopController(out, Limits(2.0, 1.0), estop=None)
    pool = ThreadPoolExecutor(1)
    soon = []
    channel = Channel()
    glue = TeleopChannel(channel, controller, "alice", {"deadman_s": 0.3}, 4096, call_soon=lambda fn, *a: soon.append(
        (fn, a)), pool=pool)

    def settle():
        pool.submit(lambda: None).result(5)  # every queued frame judged
        while soon:
            fn, args = soon.pop(0)
            fn(*args)  # what the loop would run
    yield glue, channel, out, controller, settle
    pool.shutdown()
    controller.close()


def test_hello_then_drive_then_close_zeroes(rig):
    glue, channel, out, controller, settle = rig
    hello = channel.sent[0]
    assert hello["type"] == "hello" and hello["transport"] == "datachannel" and hello["name"] == "alice"
    assert hello["deadman_s"] == 0.3 and hello["epoch"] == 0
    glue.on_message(json.dumps({"linear": 0.5, "angular": -1.0, "epoch": 0}))
    settle()
    assert out.sent == [(1.0, -1.0)]
    assert any(m["type"] == "state" and m["reason"] == "in_control" for m in channel.sent)
    glue.close()
    assert out.sent[-1] == (0.0, 0.0) and controller.state()["holder"] is None
    glue.on_message(json.dumps({"linear": 0.5, "angular": 0.0, "epoch": 0}))  # after close: ignored
    settle()
    assert out.sent[-1] == (0.0, 0.0)


def test_error_frames_come_back_on_the_channel(rig):
    glue, channel, out, controller, settle = rig
    glue.on_message('{"linear": 2, "angular": 0}')
    settle()
    assert channel.sent[-1]["type"] == "error" and channel.sent[-1]["error"] == "out_of_range"
    assert not channel.closed and out.sent == []


def test_a_frame_a_socket_is_closed_for_closes_the_channel_and_stops(rig):
    glue, channel, out, controller, settle = rig
    glue.on_message(json.dumps({"linear": 0.5, "angular": 0.0, "epoch": 0}))
    glue.on_message(b"\x00binary")
    settle()
    assert channel.sent[-1]["error"] == "binary_frame"
    assert channel.closed and glue.closed and out.sent[-1] == (0.0, 0.0)


def test_the_channel_gets_a_measuring_ping_and_a_link_state_every_link_s():
    """As the socket does: the Drive card's link figures and its too-poor banner need them."""
    from rover_web.teleop.datachannel import LINK_S

    controller = TeleopController(Output(), Limits(2.0, 1.0), estop=None)
    pool = ThreadPoolExecutor(1)
    soon, later, channel = [], [], Channel()
    glue = TeleopChannel(channel, controller, "alice", {}, 4096, call_soon=lambda fn, *a: soon.append((fn, a)),
                         call_later=lambda delay, fn, *a: later.append((delay, fn, a)) or Handle(), pool=pool)

    def settle():
        pool.submit(lambda: None).result(5)
        while soon:
            fn, args = soon.pop(0)
            fn(*args)

    def tick():
        delay, fn, args = later.pop(0)
        assert delay == LINK_S
        fn(*args)
        settle()
    try:
        tick()
        ping = next(m for m in channel.sent if m["type"] == "ping")
        state = next(m for m in channel.sent if m["type"] == "state")
        assert state["reason"] == "link" and state["link"]["rtt_ms"] is None and "quality" in state["link"]
        glue.on_message(json.dumps({"pong": ping["id"]}))
        settle()
        channel.sent.clear()
        tick()
        state = next(m for m in channel.sent if m["type"] == "state")
        assert state["reason"] == "link" and state["link"]["rtt_ms"] is not None
        assert len(later) == 1  # one timer at a time
        glue.close()
        assert later == [] or Handle.cancelled
    finally:
        pool.shutdown()
        controller.close()


class Handle:
    cancelled = False

    def cancel(self):
        Handle.cancelled = True
