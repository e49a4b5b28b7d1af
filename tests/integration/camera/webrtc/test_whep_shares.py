"""WHEP sessions take their places through the same shares as every other stream (issue 27):
one client holds only its share of the WebRTC viewer places, of the stream cap and of the camera
encodings, and never the slots kept for driving. Against a live server with aiortc clients."""

import pytest
import requests

from rover_web.camera.webrtc.service import WebRtcService
from tests.integration.camera.webrtc.conftest import LOOPBACK_ONLY
from tests.support.auth import bearer
from tests.support.teleop_support import TeleopClient
from tests.support.waiting import wait_until
from tests.support.whep import WhepRefused

IMAGE = "msg_type=sensor_msgs/msg/Image"
pytestmark = pytest.mark.ros


@pytest.fixture
def signed_webrtc(signed_server_factory):
    return lambda **settings: signed_server_factory(**{**LOOPBACK_ONLY, **settings})


def refused(whep, server, query: str, headers: dict | None = None) -> dict:
    with pytest.raises(WhepRefused) as caught:
        whep(server.url, query, headers=headers)
    assert caught.value.status == 503, caught.value
    return caught.value.body


def sessions_of(server, user: str) -> int:
    return sum(s.user == user for s in server.rover.feature(WebRtcService).sessions())


def test_one_user_holds_only_its_share_of_the_webrtc_viewer_places(signed_webrtc, whep):
    server = signed_webrtc(ROVER_WEB_WEBRTC_MAX_VIEWERS=4, ROVER_WEB_WEBRTC_VIEWERS_PER_CLIENT=2)
    viewer = bearer(server, "viewer")
    first = whep(server.url, f"topic=/cam&{IMAGE}", headers=viewer)
    whep(server.url, f"topic=/cam&{IMAGE}", headers=viewer)
    over = refused(whep, server, f"topic=/cam&{IMAGE}", viewer)
    assert over["error"] == "too_many_webrtc_viewers"
    assert "ROVER_WEB_WEBRTC_VIEWERS_PER_CLIENT" in over["message"] and "/stream?topic=/cam" in over["message"]
    # The places left are for others...
    whep(server.url, f"topic=/cam&{IMAGE}", headers=bearer(server, "operator"))
    # ...and one the user ends is theirs again; nothing of the refused offer was kept.
    assert first.delete().status_code == 204
    assert sessions_of(server, "viewer") == 1
    whep(server.url, f"topic=/cam&{IMAGE}", headers=viewer)
    assert server.rover.streams.snapshot()["by_kind"] == {"webrtc": 3}


def test_a_webrtc_session_counts_against_the_users_share_of_the_stream_cap(signed_webrtc, whep):
    server = signed_webrtc(ROVER_WEB_MAX_STREAMS_PER_CLIENT=2)
    viewer = bearer(server, "viewer")
    events = [requests.get(server.url + "/api/events?channels=status", headers=viewer, stream=True, timeout=10)
              for _ in range(2)]
    try:
        assert [r.status_code for r in events] == [200, 200]
        over = refused(whep, server, f"topic=/cam&{IMAGE}", viewer)
        assert over["error"] == "too_many_streams" and "ROVER_WEB_MAX_STREAMS_PER_CLIENT" in over["message"]
        assert server.rover.streams.held_by("user:viewer") == 2
        whep(server.url, f"topic=/cam&{IMAGE}", headers=bearer(server, "operator"))
    finally:
        for response in events:
            response.close()


def test_one_user_holds_only_its_share_of_webrtc_encodings(signed_webrtc, whep):
    server = signed_webrtc(ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT=1)
    viewer = bearer(server, "viewer")
    whep(server.url, f"topic=/cam&{IMAGE}", headers=viewer)
    over = refused(whep, server, f"topic=/cam&{IMAGE}&width=80", viewer)
    assert over["error"] == "too_many_producers" and "ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT" in over["message"]
    whep(server.url, f"topic=/cam&{IMAGE}", headers=viewer)  # one it holds already costs nothing more
    whep(server.url, f"topic=/cam&{IMAGE}&width=80", headers=bearer(server, "operator"))
    assert len(server.rover.feature(WebRtcService).producers) == 2


def test_webrtc_viewers_leave_the_slots_kept_for_driving(webrtc_server, whep):
    server = webrtc_server(ROVER_WEB_MAX_STREAMS=3, ROVER_WEB_STREAMS_RESERVED=2)
    whep(server.url, f"topic=/cam&{IMAGE}")
    over = refused(whep, server, f"topic=/cam&{IMAGE}")
    assert over["error"] == "too_many_streams" and "ROVER_WEB_STREAMS_RESERVED" in over["message"]
    # The operator's Drive card still connects, in two tabs.
    drives = []
    try:
        drives = [TeleopClient(server.url, name=f"drive {n}") for n in (1, 2)]
        assert all(d.hello["type"] == "hello" for d in drives)
        assert server.rover.streams.snapshot()["by_kind"] == {"webrtc": 1, "teleop": 2}
    finally:
        for drive in drives:
            drive.close()
    wait_until(lambda: server.rover.streams.count == 1, what="the sockets' slots given back")
