"""WHEP against a camera in another process, with an aiortc client in the test: frames decoded at
the right size over 127.0.0.1 only, refusals that leak nothing, DELETE, the caps, idle sessions,
revocation and shutdown."""

import threading
import time

import psutil
import pytest
import requests

from rover_web.camera.webrtc.service import WebRtcService
from tests.support.waiting import wait_until
from tests.support.whep import WhepRefused

IMAGE = "msg_type=sensor_msgs/msg/Image"
pytestmark = pytest.mark.ros


def service(server) -> WebRtcService:
    return server.rover.feature(WebRtcService)


def udp_ports() -> set:
    """This process's UDP sockets on 127.0.0.1 outside DDS's well-known ports: ICE's."""
    return {c.laddr.port for c in psutil.Process().net_connections(kind="udp")
            if c.laddr and c.laddr.ip == "127.0.0.1" and c.laddr.port >= 32768}


def footprint(server) -> dict:
    rover = server.rover
    return {"sessions": len(service(server).sessions()), "slots": rover.streams.count,
            "producers": len(service(server).producers), "udp": len(udp_ports()),
            # The in-process server's request threads come and go with each request (and the
            # previous test's): not counted; every thread the app keeps is.
            "threads": sum("process_request_thread" not in t.name for t in threading.enumerate())}


def wait_frames(client, count=10, timeout=20.0):
    wait_until(lambda: len(client.frames) >= count, timeout, f"{count} decoded frames")
    return list(client.frames)


def only_loopback(client):
    assert client.answer_candidates() and all(c == ("127.0.0.1", "host") for c in client.answer_candidates())
    pairs = client.nominated()
    assert pairs and all(pair == ("127.0.0.1", "127.0.0.1") for pair in pairs), pairs


def test_frames_arrive_decoded_at_the_cameras_size_and_at_the_asked_size(webrtc_server, camera, whep):
    server = webrtc_server()
    camera("/cam", width=320, height=240, hz=30)
    full = whep(server.url, f"topic=/cam&{IMAGE}")
    frames = wait_frames(full)
    assert {(w, h) for _, w, h in frames} == {(320, 240)}
    only_loopback(full)
    small = whep(server.url, f"topic=/cam&{IMAGE}&width=160")
    assert {(w, h) for _, w, h in wait_frames(small)} == {(160, 120)}
    described = requests.get(server.url + "/api/camera/whep", timeout=5).json()
    assert len(described["sessions"]) == 2 and all(s["state"] == "connected" for s in described["sessions"])
    assert "id" not in described["sessions"][0]  # ids are the capability to DELETE: never listed
    # Both viewers of /cam at 320x240 and 160 wide: two producers, one per asked size.
    assert len(service(server).producers) == 2


def test_delete_ends_the_session_and_gives_everything_back(webrtc_server, camera, whep):
    server = webrtc_server()
    camera("/cam", width=160, height=120, hz=30)
    client = whep(server.url, f"topic=/cam&{IMAGE}")
    wait_frames(client, 3)
    assert server.rover.streams.snapshot()["by_kind"] == {"webrtc": 1}
    assert client.location.startswith("/api/camera/whep/")
    response = client.delete()
    assert response.status_code == 204
    assert service(server).sessions() == [] and server.rover.streams.count == 0
    wait_until(lambda: client.connection_state in ("closed", "failed"), 30, "the client sees the end")
    again = client.delete()
    assert again.status_code == 404 and again.json()["error"] == "unknown_session"


def test_bad_offers_get_4xx_json_and_leak_nothing(webrtc_server, camera, whep, ros_peer):
    server = webrtc_server()
    camera("/cam", width=160, height=120, hz=30)
    peer = ros_peer()
    peer.advertise("/chatter", "std_msgs/msg/String")
    wait_until(lambda: "/chatter" in {t["name"] for t in requests.get(server.url + "/api/topics", timeout=5)
                                      .json()["topics"]}, 15, "/chatter listed")
    warm = whep(server.url, f"topic=/cam&{IMAGE}")  # pools and the loop warmed: the baseline is steady
    wait_frames(warm, 3)
    warm.delete()
    warm.close()
    wait_until(lambda: footprint(server)["udp"] == 0, 10, "the warm-up's sockets closed")
    before = footprint(server)

    offer = _real_offer()  # made by a real peer, for the cases that need one
    url = server.url + "/api/camera/whep"
    sdp = {"Content-Type": "application/sdp"}
    cases = [
        (url + f"?topic=/cam&{IMAGE}", "v=0\r\no=- 0 0 IN IP4 127.0.0.1\r\nm=video x\r\nthis is not sdp\r\n", sdp,
         400, "bad_sdp"),
        (url + f"?topic=/cam&{IMAGE}", "hello", sdp, 400, "bad_sdp"),
        (url + f"?topic=/cam&{IMAGE}", offer, {"Content-Type": "application/json"}, 415, "unsupported_media_type"),
        (url + f"?topic=/cam&{IMAGE}", offer, {"Content-Type": "text/plain"}, 415, "unsupported_media_type"),
        (url + "?topic=/nobody_here", offer, sdp, 404, "unknown_topic"),
        (url + "?topic=/chatter", offer, sdp, 400, "not_an_image_topic"),
        (url + "?topic=/chatter&msg_type=sensor_msgs/msg/Image", offer, sdp, 400, "type_mismatch"),
        (url + "?topic=bad%20name", offer, sdp, 400, "bad_topic"),
        (url + f"?topic=/cam&{IMAGE}&width=0x", offer, sdp, 400, "bad_type"),
        (url + "?topic=/cam&msg_type=std_msgs/msg/String", offer, sdp, 400, "not_an_image_type"),
        (url + f"?topic=/cam&{IMAGE}", _without_video(offer), sdp, 400, "no_video"),
        (url + f"?topic=/cam&{IMAGE}", offer.replace("a=ice-ufrag:", "a=x-nothing:"), sdp, 400, "bad_sdp"),
        (url + f"?topic=/cam&{IMAGE}", _without_fingerprints(offer), sdp, 400, "bad_sdp"),
        (url + f"?topic=/cam&{IMAGE}", _only_hostile_candidates(offer), sdp, 400, "no_usable_candidates"),
    ]
    for target, body, headers, status, code in cases:
        response = requests.post(target, data=body, headers=headers, timeout=15)
        what = f"{target} {headers} {body[:40]!r}: {response.status_code} {response.text[:200]}"
        assert response.status_code == status, what
        assert response.headers["Content-Type"] == "application/json", what
        assert response.json()["error"] == code, what
        assert response.json()["message"], what

    wait_until(lambda: footprint(server) == before, 10, f"back to {before} (now {footprint(server)})")


def _real_offer() -> str:
    """An SDP offer from an aiortc peer that is then thrown away (its candidates on 127.0.0.1)."""
    from aiortc import RTCConfiguration, RTCPeerConnection

    from rover_web.camera.webrtc.ice import only_host_addresses
    from rover_web.camera.webrtc.loop import LoopThread

    async def make():
        with only_host_addresses(["127.0.0.1"]):
            pc = RTCPeerConnection(RTCConfiguration(iceServers=[]))
            pc.addTransceiver("video", direction="recvonly")
            pc.createDataChannel("teleop", ordered=False, maxRetransmits=0)
            await pc.setLocalDescription(await pc.createOffer())
            sdp = pc.localDescription.sdp
            await pc.close()
            return sdp

    loop = LoopThread("offer-maker")
    loop.start()
    try:
        return loop.run(make(), 10)
    finally:
        loop.stop()


def _without_fingerprints(offer: str) -> str:
    return "\r\n".join(line for line in offer.split("\r\n") if not line.startswith("a=fingerprint:"))


def _without_video(offer: str) -> str:
    """The offer's data channel section only (the video section and its BUNDLE entry dropped)."""
    head, *sections = offer.split("\r\nm=")
    kept = [s for s in sections if not s.startswith("video")]
    return "\r\nm=".join([head.replace("BUNDLE 0 1", "BUNDLE 1"), *kept])


def test_the_viewer_cap_answers_503_pointing_to_mjpeg(webrtc_server, camera, whep):
    server = webrtc_server(ROVER_WEB_WEBRTC_MAX_VIEWERS=1)
    camera("/cam", width=160, height=120, hz=30)
    first = whep(server.url, f"topic=/cam&{IMAGE}")
    with pytest.raises(WhepRefused) as refused:
        whep(server.url, f"topic=/cam&{IMAGE}")
    assert refused.value.status == 503
    assert refused.value.body["error"] == "too_many_webrtc_viewers"
    assert "/stream?topic=/cam" in refused.value.body["message"]
    first.delete()
    whep(server.url, f"topic=/cam&{IMAGE}")  # the place is free again


def test_each_session_holds_a_slot_of_the_stream_cap(webrtc_server, camera, whep):
    server = webrtc_server(ROVER_WEB_MAX_STREAMS=1)
    camera("/cam", width=160, height=120, hz=30)
    whep(server.url, f"topic=/cam&{IMAGE}")
    with pytest.raises(WhepRefused) as refused:
        whep(server.url, f"topic=/cam&{IMAGE}")
    assert (refused.value.status, refused.value.body["error"]) == (503, "too_many_streams")
    mjpeg = requests.get(server.url + f"/stream?topic=/cam&{IMAGE}", timeout=5, stream=True)
    assert (mjpeg.status_code, mjpeg.json()["error"]) == (503, "too_many_streams")


def test_a_session_never_connected_is_closed_after_the_idle_timeout(webrtc_server, camera):
    server = webrtc_server(ROVER_WEB_WEBRTC_IDLE_TIMEOUT_S=1.0)
    camera("/cam", width=160, height=120, hz=30)
    answered = requests.post(server.url + f"/api/camera/whep?topic=/cam&{IMAGE}", data=_real_offer(),
                             headers={"Content-Type": "application/sdp"}, timeout=15)
    assert answered.status_code == 201  # the offering peer is gone: nobody answers the ICE checks
    assert len(service(server).sessions()) == 1 and server.rover.streams.count == 1
    wait_until(lambda: not service(server).sessions(), 15, "the idle session closed")
    assert server.rover.streams.count == 0
    wait_until(lambda: not udp_ports(), 10, "its sockets closed")


def test_close_sessions_of_a_user_closes_their_peer_connections_only(signed_server, camera, whep):
    server = signed_server
    camera("/cam", width=160, height=120, hz=30)
    as_viewer = whep(server.url, f"topic=/cam&{IMAGE}", headers={"Authorization": f"Bearer {server.tokens['viewer']}"})
    as_operator = whep(server.url, f"topic=/cam&{IMAGE}",
                       headers={"Authorization": f"Bearer {server.tokens['operator']}"})
    wait_frames(as_viewer, 3)
    wait_frames(as_operator, 3)
    assert {s.user for s in service(server).sessions()} == {"viewer", "operator"}
    assert service(server).close_sessions_of("viewer") == 1
    wait_until(lambda: as_viewer.connection_state in ("closed", "failed"), 30, "the viewer's connection ended")
    assert [s.user for s in service(server).sessions()] == ["operator"]
    seen = len(as_operator.frames)
    wait_until(lambda: len(as_operator.frames) > seen + 5, 10, "the operator still receives frames")


@pytest.mark.parametrize("caller, status", [(None, 401), ("viewer", 201), ("operator", 201)])
def test_whep_needs_the_viewer_role(signed_server, camera, whep, caller, status):
    camera("/cam", width=160, height=120, hz=30)
    headers = {"Authorization": f"Bearer {signed_server.tokens[caller]}"} if caller else {}
    if status == 201:
        client = whep(signed_server.url, f"topic=/cam&{IMAGE}", headers=headers)
        someone = "admin" if caller == "viewer" else "viewer"
        other = requests.delete(signed_server.url + client.location, timeout=5,
                                headers={"Authorization": f"Bearer {signed_server.tokens[someone]}"})
        # An admin may end anyone's session; a viewer may not end an operator's.
        assert other.status_code == (204 if caller == "viewer" else 404)
        return
    with pytest.raises(WhepRefused) as refused:
        whep(signed_server.url, f"topic=/cam&{IMAGE}", headers=headers)
    assert refused.value.status == status and refused.value.body["error"] == "unauthenticated"


def test_shutdown_closes_every_session(webrtc_server, camera, whep):
    server = webrtc_server()
    camera("/cam", width=160, height=120, hz=30)
    clients = [whep(server.url, f"topic=/cam&{IMAGE}") for _ in range(2)]
    for client in clients:
        wait_frames(client, 3)
    server.rover.shutdown()
    assert service(server).sessions() == [] and server.rover.streams.count == 0
    assert not [t.name for t in threading.enumerate() if t.name.startswith(("webrtc-loop", "webrtc-frames",
                                                                            "webrtc-teleop"))]
    for client in clients:
        wait_until(lambda c=client: c.connection_state in ("closed", "failed"), 40, "the client sees the end")
    wait_until(lambda: not udp_ports() or all(not c.pc or c.connection_state == "closed" for c in clients), 5,
               "sockets")
    time.sleep(0)


def _candidate_lines(offer: str) -> list[str]:
    return [line for line in offer.split("\r\n") if line.startswith("a=candidate:")]


def _with_candidates(offer: str, extra: list[str], drop_own: bool = False) -> str:
    """The offer with `extra` candidate lines where its first candidate is (its own dropped if asked)."""
    lines = offer.split("\r\n")
    at = next(i for i, line in enumerate(lines) if line.startswith("a=candidate:"))
    kept = [line for line in lines if not (drop_own and line.startswith("a=candidate:"))]
    return "\r\n".join(kept[:at] + extra + kept[at:])


def _only_hostile_candidates(offer: str) -> str:
    return _with_candidates(offer, ["a=candidate:9 1 udp 2130706431 224.0.0.251 5353 typ host",
                                    "a=candidate:8 1 udp 2130706431 127.0.0.1 53 typ host",
                                    "a=candidate:7 1 udp 2130706431 255.255.255.255 9999 typ host"], drop_own=True)


def test_an_offer_s_remote_candidates_are_capped(webrtc_server, camera):
    """The review's offer with 300 candidates had the robot send STUN to 300 ports the client chose:
    here 40 listening sockets are offered, and at most MAX_REMOTE_CANDIDATES of them hear anything."""
    import socket

    from rover_web.camera.webrtc.ice import MAX_REMOTE_CANDIDATES

    server = webrtc_server()
    camera("/cam", width=160, height=120, hz=30)
    sockets = []
    for _ in range(40):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        s.setblocking(False)
        sockets.append(s)
    try:
        extra = [f"a=candidate:x{i} 1 udp 2130706431 127.0.0.1 {s.getsockname()[1]} typ host"
                 for i, s in enumerate(sockets)]
        response = requests.post(server.url + f"/api/camera/whep?topic=/cam&{IMAGE}",
                                 data=_with_candidates(_real_offer(), extra, drop_own=True),
                                 headers={"Content-Type": "application/sdp"}, timeout=15)
        assert response.status_code == 201, response.text
        heard: set[int] = set()
        deadline = time.monotonic() + 4.0  # aioice checks each pair several times in its first seconds
        while time.monotonic() < deadline:
            for i, s in enumerate(sockets):
                try:
                    while s.recv(2048):
                        heard.add(i)
                except BlockingIOError:
                    pass
            time.sleep(0.05)
        assert 0 < len(heard) <= MAX_REMOTE_CANDIDATES, heard
        requests.delete(server.url + response.headers["Location"], timeout=10)
    finally:
        for s in sockets:
            s.close()
