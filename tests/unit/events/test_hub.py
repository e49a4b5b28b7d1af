import json
import threading
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.events.hub import EventHub, TooManyClients


def frames(raw: bytes) -> list[tuple[str, dict, int]]:
    out = []
    for block in raw.decode().split("\n\n"):
        if not block:
            continue
        fields = dict(line.split(": ", 1) for line in block.split("\n"))
        out.append((fields["event"], json.loads(fields["data"]), int(fields["id"])))
    return out


def test_snapshot_has_latest_value_of_each_requested_channel_only():
    hub = EventHub()
    hub.publish("pose", {"x": 1})
    hub.publish("pose", {"x": 2})
    hub.publish("status", {"ok": True})
    with hub.subscribe(["pose"]) as sub:
        assert [(e, d) for e, d, _ in frames(sub.snapshot())] == [("pose", {"x": 2})]


def test_slow_reader_gets_only_the_newest_value():
    hub = EventHub()
    with hub.subscribe(["pose", "goal"]) as sub:
        sub.snapshot()
        for i in range(1000):
            hub.publish("pose", {"x": i})
        hub.publish("goal", {"g": 1})
        got = frames(sub.wait(0.1))
    assert [(e, d) for e, d, _ in got] == [("pose", {"x": 999}), ("goal", {"g": 1})]
    assert got[0][2] < got[1][2]  # ordered by sequence


def test_wait_times_out_with_empty_bytes_and_wakes_on_publish():
    hub = EventHub()
    with hub.subscribe(["a"]) as sub:
        sub.snapshot()
        t0 = time.monotonic()
        assert sub.wait(0.05) == b""
        assert time.monotonic() - t0 >= 0.04
        threading.Timer(0.05, hub.publish, args=("a", 1)).start()
        assert frames(sub.wait(5))[0][1] == 1


def test_other_channels_do_not_produce_frames():
    hub = EventHub()
    with hub.subscribe(["a"]) as sub:
        sub.snapshot()
        hub.publish("b", 1)
        assert sub.wait(0.01) == b""


def test_ring_events_are_not_conflated_and_replay_after_last_event_id():
    hub = EventHub(ring_size=8)
    with hub.subscribe(["code"]) as live:
        live.snapshot()
        ids = [hub.emit("code", {"n": n}) for n in range(3)]
        assert [d["n"] for _, d, _ in frames(live.wait(0.1))] == [0, 1, 2]
    with hub.subscribe(["code"], last_event_id=ids[0]) as reconnecting:
        assert [d["n"] for _, d, _ in frames(reconnecting.snapshot())] == [1, 2]


def test_ring_is_bounded():
    hub = EventHub(ring_size=4)
    for n in range(100):
        hub.emit("code", n)
    with hub.subscribe(["code"], last_event_id=0) as sub:
        assert [d for _, d, _ in frames(sub.snapshot())] == [96, 97, 98, 99]


def test_each_event_is_serialised_once_and_shared():
    hub = EventHub()
    hub.publish("pose", {"x": 1})
    subs = [hub.subscribe(["pose"]) for _ in range(3)]
    for s in subs:
        s.snapshot()
    hub.publish("pose", {"x": 2})
    chunks = [s.wait(0.1) for s in subs]
    assert chunks[0] == chunks[1] == chunks[2]
    for s in subs:
        s.close()


def test_client_count_and_limit():
    hub = EventHub(max_clients=2)
    a, b = hub.subscribe(["x"]), hub.subscribe(["x"])
    assert hub.client_count == 2
    with pytest.raises(TooManyClients):
        hub.subscribe(["x"])
    a.close()
    a.close()  # idempotent
    assert hub.client_count == 1
    b.close()
    assert hub.client_count == 0


def test_close_ends_waiting_subscribers():
    hub = EventHub()
    sub = hub.subscribe(["x"])
    sub.snapshot()
    threading.Timer(0.05, hub.close).start()
    assert sub.wait(5) is None


def test_non_finite_values_are_refused_at_publish():
    hub = EventHub()
    with pytest.raises(ValueError):
        hub.publish("x", {"v": float("nan")})
    assert hub.latest("x") is None


def test_throttled_publish_limits_rate_and_always_delivers_the_last_value():
    hub = EventHub()
    with hub.subscribe(["odom"]) as sub:
        sub.snapshot()
        for i in range(100):
            hub.publish_throttled("odom", {"i": i}, max_hz=20)
        first = frames(sub.wait(0.01))
        assert [d for _, d, _ in first] == [{"i": 0}]
        later = frames(sub.wait(1.0))
        assert [d for _, d, _ in later] == [{"i": 99}]  # the burst's last value, after the interval

def test_held_values_of_every_channel_go_out_from_one_thread_that_ends_with_the_hub():
    hub = EventHub()
    channels = [f"c{i}" for i in range(10)]
    before = threading.active_count()
    with hub.subscribe(channels) as sub:
        sub.snapshot()
        for burst in range(3):
            for channel in channels:
                for i in range(5):
                    hub.publish_throttled(channel, {"burst": burst, "i": i}, max_hz=50)
            assert threading.active_count() <= before + 1  # one flusher, not a timer per held value
        got = {}
        deadline = time.monotonic() + 5
        while len(got) < len(channels) or any(v != {"burst": 2, "i": 4} for v in got.values()):
            assert time.monotonic() < deadline, got
            for channel, data, _ in frames(sub.wait(0.5)):
                got[channel] = data
    flusher = hub._flusher
    hub.close()
    flusher.join(2)
    assert not flusher.is_alive()


def test_a_value_that_goes_out_directly_drops_the_older_held_one():
    hub = EventHub()
    with hub.subscribe(["odom"]) as sub:
        sub.snapshot()
        hub.publish_throttled("odom", {"i": 0}, max_hz=10)
        assert [d for _, d, _ in frames(sub.wait(0.01))] == [{"i": 0}]
        hub.publish_throttled("odom", {"i": 1}, max_hz=10)  # held until 0.1 s after the first
        time.sleep(0.01)
        hub.publish_throttled("odom", {"i": 2}, max_hz=1000)  # its own interval is up: out at once
        assert [d for _, d, _ in frames(sub.wait(0.01))] == [{"i": 2}]
        assert sub.wait(0.2) == b""  # past the held value's time, and it never came
    hub.close()


_ops = st.lists(st.tuples(st.sampled_from(["publish", "emit", "poll"]), st.sampled_from(["a", "b", "c"])),
                max_size=60)


@settings(max_examples=200, deadline=None)
@given(_ops)
def test_poll_returns_what_changed_since_the_last_poll_whatever_the_polling_pattern(ops):
    """Against a model: the newest value of each subscribed channel changed since the last poll, and
    every subscribed ring event since then, in sequence order. One client polls after every change
    (the broadcaster's fast path), the other only when the operations say so."""
    hub = EventHub()
    log = []  # (seq, kind, channel, value)
    every, sometimes = hub.subscribe(["a", "b"]), hub.subscribe(["a", "b"])
    every.snapshot(), sometimes.snapshot()
    cursors = {"every": 0, "sometimes": 0}

    def expected(cursor):
        latest = {}
        events = []
        for seq, kind, channel, value in log:
            if seq <= cursor or channel not in ("a", "b"):
                continue
            if kind == "publish":
                latest[channel] = (seq, channel, value)
            else:
                events.append((seq, channel, value))
        return sorted([*latest.values(), *events])

    def check(name, sub):
        got = [(seq, event, data["v"]) for event, data, seq in frames(sub.poll())]
        assert got == expected(cursors[name])
        cursors[name] = len(log)

    for i, (op, channel) in enumerate(ops):
        if op == "poll":
            check("sometimes", sometimes)
            continue
        getattr(hub, op)(channel, {"v": i})
        log.append((len(log) + 1, op, channel, i))
        check("every", every)
    check("sometimes", sometimes)


def test_watchers_counts_the_open_streams_of_each_channel():
    hub = EventHub()
    hub.register("markers", "scan", "odom")
    a = hub.subscribe(["markers", "odom"])
    b = hub.subscribe(["markers"])
    assert (hub.watchers("markers"), hub.watchers("odom"), hub.watchers("scan")) == (2, 1, 0)
    a.close()
    a.close()  # twice: counted once
    assert (hub.watchers("markers"), hub.watchers("odom")) == (1, 0)
    with b:
        pass
    assert hub.watchers("markers") == 0 and hub.client_count == 0
