"""Which candidates and ICE servers a peer connection may use: candidate filtering, the setting's
ICE server syntax, and host gathering restricted to the chosen addresses (a real aiortc peer)."""

import asyncio

import pytest
from aiortc import RTCConfiguration, RTCPeerConnection

from rover_web.camera.webrtc.ice import (
    candidates,
    check_addresses,
    filter_candidates,
    only_host_addresses,
    parse_ice_server,
)

SDP = "\r\n".join([
    "v=0", "m=video 9 UDP/TLS/RTP/SAVPF 96",
    "a=candidate:1 1 udp 2130706431 192.0.2.2 50000 typ host",
    "a=candidate:2 1 udp 2130706431 127.0.0.1 50001 typ host",
    "a=candidate:3 1 udp 1694498815 203.0.113.9 50002 typ srflx raddr 192.0.2.2 rport 50000",
    "a=end-of-candidates", "",
])


def test_filter_keeps_only_allowed_host_candidates():
    kept = candidates(filter_candidates(SDP, ["127.0.0.1"]))
    assert kept == [("127.0.0.1", "host"), ("203.0.113.9", "srflx")]
    assert filter_candidates(SDP, []) == SDP  # nothing chosen: nothing dropped


def test_ice_server_entries():
    assert parse_ice_server("stun:stun.example.org:3478") == {"urls": "stun:stun.example.org:3478"}
    assert parse_ice_server("turn:me:s3cret@turn.example.org:3478?transport=udp") == {
        "urls": "turn:turn.example.org:3478?transport=udp", "username": "me", "credential": "s3cret"}
    for bad in ("http://x", "turn:turn.example.org:3478", "stun:", "stun:a b"):
        with pytest.raises(ValueError):
            parse_ice_server(bad)


def test_addresses_must_be_ip_literals():
    assert check_addresses([" 127.0.0.1", "::1"]) == ("127.0.0.1", "::1")
    with pytest.raises(ValueError):
        check_addresses(["localhost"])


def gathered(addresses):
    async def run():
        with only_host_addresses(addresses):
            pc = RTCPeerConnection(RTCConfiguration(iceServers=[]))
            pc.addTransceiver("video", direction="recvonly")
            await pc.setLocalDescription(await pc.createOffer())
        sdp = pc.localDescription.sdp
        await pc.close()
        return candidates(sdp)
    return asyncio.run(run())


def test_gathering_uses_only_the_chosen_addresses():
    assert gathered(["127.0.0.1"]) == [("127.0.0.1", "host")]
    # Outside the block, aioice's own choice again (every interface but loopback; this machine
    # may have none, so only "not restricted to ours" is checked).
    assert ("127.0.0.1", "host") not in gathered(None)


def test_remote_candidates_are_screened_and_capped():
    from rover_web.camera.webrtc.ice import MAX_REMOTE_CANDIDATES, screen_remote_candidates

    hostile = [f"a=candidate:h{i} 1 udp 2130706431 {address} {port} typ host"
               for i, (address, port) in enumerate([("224.0.0.251", 5353), ("255.255.255.255", 4000),
                                                    ("192.168.1.255", 4000), ("0.0.0.0", 4000), ("::", 4000),
                                                    ("ff02::1", 4000), ("127.0.0.1", 0), ("127.0.0.1", 53),
                                                    ("printer.local", 4000), ("example.com", 4000)])]
    many = [f"a=candidate:m{i} 1 udp 2130706431 127.0.0.1 {20000 + i} typ host" for i in range(300)]
    offer = "\r\n".join(["v=0", "m=video 9 UDP/TLS/RTP/SAVPF 96", *hostile, *many, "a=end-of-candidates", ""])
    screened, kept, dropped = screen_remote_candidates(offer)
    assert (kept, dropped) == (MAX_REMOTE_CANDIDATES, len(hostile) + 300 - MAX_REMOTE_CANDIDATES)
    assert candidates(screened) == [("127.0.0.1", "host")] * MAX_REMOTE_CANDIDATES
    only_hostile = "\r\n".join(["v=0", "m=video 9 UDP/TLS/RTP/SAVPF 96", *hostile, ""])
    assert screen_remote_candidates(only_hostile)[1:] == (0, len(hostile))
    assert screen_remote_candidates(SDP) == (SDP, 3, 0)  # an ordinary offer is left as it is
