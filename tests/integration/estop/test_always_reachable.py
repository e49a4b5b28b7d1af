"""The e-stop stays reachable when long-lived streams take every thread they may have."""

import sys
import time

import requests

from tests.conftest import free_port
from tests.support.teleop_support import TeleopClient
from tests.support.waiting import wait_until

CAP = 8


def test_with_the_stream_cap_reached_the_e_stop_is_answered_at_once(server_process, sse_client):
    """Under gunicorn, whose threads are the real limit: cap + 16 threads (gunicorn.conf.py)."""
    port = free_port()
    server = server_process(port=port, env={"ROVER_WEB_PORT": str(port), "ROVER_WEB_MAX_STREAMS": str(CAP)},
                            args=[sys.executable, "-m", "gunicorn", "-c", "gunicorn.conf.py",
                                  "rover_web:create_app()"]).start()
    streams = [sse_client(server.url + "/api/events?channels=status") for _ in range(CAP - 2)]
    sockets = [TeleopClient(server.url, name=f"tab {i}") for i in range(2)]
    for stream in streams:
        stream.wait_for("status")
    wait_until(lambda: requests.get(server.url + "/api/status", timeout=5).json()["streams"]["open"] == CAP,
               what="every slot taken")

    # Over the cap: each kind of stream is refused at once with 503, and holds no thread.
    over = requests.get(server.url + "/api/events?channels=status", stream=True, timeout=5)
    assert over.status_code == 503 and over.json()["error"] == "too_many_streams"
    echo = requests.get(server.url + "/api/topics/echo?topic=/rosout", stream=True, timeout=5)
    assert echo.status_code == 503
    camera = requests.get(server.url + "/stream?topic=/camera/image_raw", stream=True, timeout=5)
    assert camera.status_code == 503
    refused_socket = requests.get(server.url + "/ws/teleop", timeout=5, headers={
        "Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
        "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="})
    assert refused_socket.status_code == 503

    times = []
    for _ in range(5):
        t0 = time.monotonic()
        response = requests.post(server.url + "/api/estop", json={"engaged": True}, timeout=5)
        times.append(time.monotonic() - t0)
        assert response.status_code == 200 and response.json()["engaged"] is True
    assert max(times) < 0.2, times

    # A stream that ends gives its slot back.
    streams[0].close()
    wait_until(lambda: requests.get(server.url + "/api/status", timeout=5).json()["streams"]["open"] == CAP - 1,
               what="the slot given back")
    sse_client(server.url + "/api/events?channels=status").wait_for("status")
    for client in sockets:
        client.close()
    assert "Traceback" not in server.log(), server.log()
