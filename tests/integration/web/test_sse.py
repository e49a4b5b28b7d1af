"""The SSE endpoint served for real: framing, snapshot, conflation, keep-alive, clean-up, many clients."""

import gc
import time

import psutil
import requests


def wait_until(predicate, timeout=10.0, interval=0.02):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(interval)
    return True


def test_retry_first_then_snapshot_of_each_requested_channel(live_server, sse_client):
    hub = live_server.rover.hub
    hub.publish("odom", {"x": 1.0, "y": 0.0, "yaw": 0.0, "linear": 0.0, "angular": 0.0, "frame_id": "odom"})
    stream = sse_client(live_server.url + "/api/events?channels=odom,status")
    stream.wait_for("status")
    assert stream.status == 200
    assert stream.first_field == "retry" and stream.retry_ms == live_server.rover.config["ROVER_WEB_SSE_RETRY_MS"]
    first_two = {e["event"] for e in stream.events[:2]}
    assert first_two == {"odom", "status"}
    assert stream.of("odom")[0]["json"]["x"] == 1.0
    assert all(e["id"] is not None for e in stream.events)


def test_unknown_or_missing_channels_are_a_json_400(live_server):
    for query in ("", "?channels=", "?channels=status,nope"):
        r = requests.get(live_server.url + "/api/events" + query, timeout=5)
        assert r.status_code == 400
        assert r.headers["Content-Type"].startswith("application/json")
        assert "known: " in r.json()["message"] and "status" in r.json()["message"]


def test_slow_reader_gets_newest_value_not_a_backlog(live_server, sse_client):
    hub = live_server.rover.hub
    hub.register("bench")
    stream = sse_client(live_server.url + "/api/events?channels=bench", read_delay_s=0.2)
    time.sleep(0.3)
    pad = "x" * 4000  # 5000 frames of 4 KB: 20 MB if queued, a few socket buffers if conflated
    for i in range(5000):
        hub.publish("bench", {"i": i, "pad": pad})
    last = stream.wait_for("bench", lambda d: d["i"] == 4999, timeout=30)
    received = [e["json"]["i"] for e in stream.of("bench")]
    assert received[-1] == 4999 and last
    # What was skipped is gone: the server kept one pending write, not a queue of 5000 frames.
    assert len(received) < 500, len(received)


def test_keepalive_comment_when_idle(live_server_factory, sse_client):
    server = live_server_factory(ROVER_WEB_SSE_KEEPALIVE_S=0.2, ROVER_WEB_STATUS_PERIOD_S=60)
    stream = sse_client(server.url + "/api/events?channels=status")
    assert wait_until(lambda: len(stream.comments) >= 3, timeout=5)
    gaps = [b[0] - a[0] for a, b in zip(stream.comments, stream.comments[1:], strict=False)]
    assert all(g < 1.0 for g in gaps)
    assert stream.comments[0][1] == " keep-alive" or "keep-alive" in stream.comments[0][1]


def test_default_keepalive_is_within_15_seconds(app):
    assert app.config["ROVER_WEB_SSE_KEEPALIVE_S"] <= 15


def test_client_count_returns_to_zero_after_disconnect(live_server, sse_client):
    hub = live_server.rover.hub
    clients = [sse_client(live_server.url + "/api/events?channels=status") for _ in range(5)]
    for c in clients:
        c.wait_for("status")
    assert hub.client_count == 5
    for c in clients:
        c.close()
    # Idle streams notice a closed browser within about a second, without waiting for a write.
    assert wait_until(lambda: hub.client_count == 0, timeout=5), hub.client_count


def test_two_hundred_clients_with_bounded_memory(live_server_factory, sse_client):
    server = live_server_factory(ROVER_WEB_SSE_MAX_CLIENTS=300, ROVER_WEB_MAX_STREAMS=300)
    hub = server.rover.hub
    hub.register("bench")
    process = psutil.Process()

    def open_clients(n):
        # The clients keep only their newest event, so this process's memory is the server's part.
        return [sse_client(server.url + "/api/events?channels=bench,status", keep_events=False) for _ in range(n)]

    warm = open_clients(20)
    for c in warm:
        c.wait_for("status")
    gc.collect()
    rss_before = process.memory_info().rss
    clients = open_clients(180)
    assert wait_until(lambda: hub.client_count == 200, timeout=30), hub.client_count
    payload = {"blob": "x" * 2000}
    for i in range(300):
        payload["i"] = i
        hub.publish("bench", dict(payload))
    for c in warm + clients:
        c.wait_for("bench", lambda d: d["i"] == 299, timeout=30)
    rss_during = process.memory_info().rss
    # 180 more streams (threads and sockets, the clients' reader threads too) within a bounded
    # budget: no per-client queue of the 300 events (that alone would be 200 x 300 x 2 KB = 120 MB).
    assert rss_during - rss_before < 60 * 1024 * 1024, (rss_during - rss_before) / 1e6
    for c in warm + clients:
        c.close()
    assert wait_until(lambda: hub.client_count == 0, timeout=10), hub.client_count


def test_stream_limit_gives_503_json(live_server_factory, sse_client):
    server = live_server_factory(ROVER_WEB_SSE_MAX_CLIENTS=2)
    a = sse_client(server.url + "/api/events?channels=status")
    b = sse_client(server.url + "/api/events?channels=status")
    a.wait_for("status")
    b.wait_for("status")
    r = requests.get(server.url + "/api/events?channels=status", timeout=5)
    assert r.status_code == 503 and r.json()["error"] == "too_many_streams"


def test_last_event_id_replays_missed_ring_events(live_server, sse_client):
    hub = live_server.rover.hub
    hub.register("log")
    first = hub.emit("log", {"n": 1})
    hub.emit("log", {"n": 2})
    hub.emit("log", {"n": 3})
    stream = sse_client(live_server.url + "/api/events?channels=log", headers={"Last-Event-ID": str(first)})
    stream.wait_for("log", lambda d: d["n"] == 3)
    assert [e["json"]["n"] for e in stream.of("log")] == [2, 3]
