"""Streams and subscriptions against a live server (issue 27): another site's page cannot open any
while sign-in is off, one client holds only its share of the stream cap, and the last slots are
kept for driving."""

import pytest
import requests

from rover_web.camera.service import CameraStreams
from rover_web.plot.service import Plots
from rover_web.topics.service import TopicBrowser
from tests.support.auth import bearer
from tests.support.teleop_support import TeleopClient
from tests.support.waiting import wait_until

CROSS_SITE = {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "no-cors", "Origin": "https://evil.example"}
UPGRADE = {"Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
           "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}

# Each GET that would create a stream or a subscription; types given, so none needs the ROS graph.
SUBSCRIBING = [
    "/api/events?channels=status",
    "/api/topics/echo?topic=/cross_site_echo&type=std_msgs/msg/String",
    "/stream?topic=/cross_site_camera&type=sensor_msgs/msg/Image",
    "/snapshot?topic=/cross_site_camera&type=sensor_msgs/msg/Image",
    "/api/plot?topic=/cross_site_plot&type=std_msgs/msg/Float64&field=data",
]


def created(server) -> dict:
    rover = server.rover
    return {"streams": rover.streams.count, "sse": rover.hub.client_count,
            "echoes": len(rover.feature(TopicBrowser).echoes), "cameras": len(rover.feature(CameraStreams).producers),
            "plots": len(rover.feature(Plots).active())}


def sse(url: str, headers: dict | None = None) -> requests.Response:
    return requests.get(url + "/api/events?channels=status", headers=headers, stream=True, timeout=10)


@pytest.fixture
def opened():
    responses = []

    def keep(response):
        responses.append(response)
        return response

    yield keep
    for response in responses:
        response.close()


def test_another_sites_page_opens_no_stream_or_subscription_while_sign_in_is_off(live_server):
    nothing = created(live_server)
    for path in SUBSCRIBING:
        r = requests.get(live_server.url + path, headers=CROSS_SITE, stream=True, timeout=10)
        assert r.status_code == 403, (path, r.status_code)
        assert r.json()["error"] == "cross_site", path
    teleop = requests.get(live_server.url + "/ws/teleop", headers={**CROSS_SITE, **UPGRADE}, timeout=10)
    assert teleop.status_code == 403
    assert created(live_server) == nothing


def test_the_same_site_and_tools_without_the_header_still_open_streams(live_server, opened):
    for headers in ({"Sec-Fetch-Site": "same-origin"}, {"Sec-Fetch-Site": "none"}, {}):
        r = opened(sse(live_server.url, headers))
        assert r.status_code == 200, headers
    wait_until(lambda: live_server.rover.hub.client_count == 3, what="three event streams")


@pytest.fixture
def signed(signed_server_factory):
    return signed_server_factory


def test_with_sign_in_on_a_signed_in_cross_site_request_is_judged_by_its_role(signed, opened):
    server = signed()
    r = opened(sse(server.url, {**CROSS_SITE, **bearer(server, "viewer")}))
    assert r.status_code == 200


def test_one_user_holds_only_its_share_of_the_stream_cap(signed, opened):
    server = signed(ROVER_WEB_MAX_STREAMS=20, ROVER_WEB_MAX_STREAMS_PER_CLIENT=3)
    viewer = bearer(server, "viewer")
    mine = [opened(sse(server.url, viewer)) for _ in range(3)]
    assert [r.status_code for r in mine] == [200, 200, 200]
    over = opened(sse(server.url, viewer))
    assert over.status_code == 503 and over.json()["error"] == "too_many_streams"
    assert "ROVER_WEB_MAX_STREAMS_PER_CLIENT" in over.json()["message"]
    # Others are not held back by that user...
    assert opened(sse(server.url, bearer(server, "operator"))).status_code == 200
    # ...and a stream the user closes is given back.
    mine[0].close()
    wait_until(lambda: server.rover.streams.held_by("user:viewer") == 2, what="the closed stream given back")
    assert opened(sse(server.url, viewer)).status_code == 200


def test_the_last_slots_are_kept_for_driving(live_server_factory, opened):
    server = live_server_factory(ROVER_WEB_MAX_STREAMS=5, ROVER_WEB_STREAMS_RESERVED=2)
    viewers = [opened(sse(server.url)) for _ in range(3)]
    assert [r.status_code for r in viewers] == [200, 200, 200]
    over = opened(sse(server.url))
    assert over.status_code == 503 and "ROVER_WEB_STREAMS_RESERVED" in over.json()["message"]
    echo = opened(requests.get(server.url + "/api/topics/echo?topic=/rosout", stream=True, timeout=10))
    assert echo.status_code == 503
    # The operator's Drive card still connects, twice (two tabs), in the reserved slots.
    first = TeleopClient(server.url, name="drive 1")
    second = TeleopClient(server.url, name="drive 2")
    try:
        assert first.hello["type"] == "hello" and second.hello["type"] == "hello"
        assert server.rover.streams.snapshot()["by_kind"] == {"sse": 3, "teleop": 2}
        # The cap itself still holds.
        refused = requests.get(server.url + "/ws/teleop", headers=UPGRADE, timeout=10)
        assert refused.status_code == 503
    finally:
        first.close()
        second.close()


def test_with_sign_in_on_an_operator_may_use_the_reserve_and_a_viewer_may_not(signed, opened):
    server = signed(ROVER_WEB_MAX_STREAMS=4, ROVER_WEB_STREAMS_RESERVED=2)
    assert [opened(sse(server.url, bearer(server, "viewer"))).status_code for _ in range(3)] == [200, 200, 503]
    operator = bearer(server, "operator")
    assert [opened(sse(server.url, operator)).status_code for _ in range(3)] == [200, 200, 503]  # then the cap


@pytest.mark.parametrize("path, code", [
    ("/api/topics/echo?topic=/share_{n}&type=std_msgs/msg/String", "too_many_subscriptions"),
    ("/stream?topic=/share_camera_{n}&type=sensor_msgs/msg/Image", "too_many_producers"),
])
def test_one_user_holds_only_its_share_of_subscriptions(signed, opened, path, code):
    server = signed(ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT=2)
    viewer = bearer(server, "viewer")

    def get(n, headers):
        return opened(requests.get(server.url + path.format(n=n), headers=headers, stream=True, timeout=10))

    assert [get(n, viewer).status_code for n in (1, 2)] == [200, 200]
    over = get(3, viewer)
    assert over.status_code == 503 and over.json()["error"] == code
    assert "ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT" in over.json()["message"]
    assert get(1, viewer).status_code == 200  # one it holds already costs nothing more
    assert get(3, bearer(server, "operator")).status_code == 200  # another user is not held back
