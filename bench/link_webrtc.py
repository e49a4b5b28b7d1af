"""bench/link.py's WebRTC viewer: an aiortc WHEP client whose media goes through the link emulator.

The WHEP POST goes through the emulator's TCP path like every other request. The media cannot
simply follow: ICE sends to the addresses the SDP names. So the harness rewrites one line. The
server (ROVER_WEB_WEBRTC_HOST_ADDRESSES=127.0.0.1) answers with one host candidate, 127.0.0.1 and
the UDP port aioice bound for this session: aioice binds port 0 (the kernel picks; aiortc offers no
way to fix it) and aiortc bundles audio, video and data channel on that one port, so the port is
known only from the answer. Before the answer is applied, the emulator's UDP target is set to that
port and the candidate's port is rewritten to the emulator's UDP listening port. The client then
sends its checks, DTLS, RTCP and data channel to the emulator, which relays them from a socket of
its own (the server learns it as a peer-reflexive candidate and, being ICE-controlled, sends on the
pair the client nominated): every media packet and every data channel message crosses the
emulated link, both ways. The offer's candidate is rewritten too, to a socket of the bench that
never reads: left as it is, the server's own checks would reach the client straight over loopback,
the client would learn the server's real port as a peer-reflexive candidate, and media would go
round the emulator (the first try did exactly that). `route()` names the pair the client uses; the
bench reports it, and it must be the emulator's UDP port.
Every candidate on both sides is 127.0.0.1: no packet goes anywhere else.
"""

from __future__ import annotations

import asyncio
import functools
import json
import re
import socket
import threading
import time

import browser_jitter
import requests
from aiortc import RTCConfiguration, RTCPeerConnection, RTCSessionDescription
from common import count_rtp_payload, decoded_frames

from rover_web.camera.webrtc.ice import candidates, filter_candidates, only_host_addresses
from rover_web.camera.webrtc.loop import LoopThread
from rover_web.sim import timecode

LOOPBACK = ["127.0.0.1"]
_HOST_CANDIDATE = re.compile(r"^(a=candidate:\S+ \d+ udp \d+ 127\.0\.0\.1 )(\d+)( typ host.*)$", re.I)


def server_port(answer: str) -> int:
    """The one UDP port of the server's host candidates (all 127.0.0.1): ValueError otherwise."""
    ports = {int(m.group(2)) for line in answer.splitlines() if (m := _HOST_CANDIDATE.match(line.strip()))}
    others = [c for c in candidates(answer) if c[0] != "127.0.0.1"]
    if len(ports) != 1 or others:
        raise ValueError(f"expected one 127.0.0.1 UDP host candidate in the answer, got ports {sorted(ports)} "
                         f"and {others}")
    return ports.pop()


def via(sdp: str, port: int) -> str:
    """The SDP with its 127.0.0.1 host candidates' port replaced by `port`."""
    out = []
    for line in sdp.splitlines():
        m = _HOST_CANDIDATE.match(line.strip())
        out.append(f"{m.group(1)}{port}{m.group(3)}" if m else line)
    return "\r\n".join(out) + "\r\n"


class LinkWhep:
    """One WHEP session through `emu` (a LinkEmulator with a UDP relay): video decoded and its time
    code read (`samples`: (arrival monotonic, age ms or None, RTP payload bytes of that frame)), and
    with `teleop`, the `teleop` data channel (unordered, no retransmits, as the page opens it)."""

    def __init__(self, emu, url: str, topic: str, *, teleop: bool = False, timeout_s: float = 30.0):
        self.emu, self.url = emu, url
        self.samples: list[tuple[float, float | None, int]] = []
        self.sizes: list[tuple[float, str]] = []  # (arrival monotonic, "WxH") of each decoded frame
        self.messages: list[dict] = []
        self.channel = None
        self.channel_open = threading.Event()
        self.cond = threading.Condition()
        self._bytes = 0  # RTP payload since the last decoded frame
        self.pc = None
        self.location = None
        # Where the offer says the client is: a socket of ours that never reads (see the docstring).
        self.sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sink.bind(("127.0.0.1", 0))
        self.loop = LoopThread("bench-whep")
        self.loop.start()
        try:
            offer = via(self.loop.run(self._offer(teleop), timeout_s), self.sink.getsockname()[1])
            response = requests.post(f"{url}/api/camera/whep?topic={topic}", data=offer, timeout=timeout_s,
                                     headers={"Content-Type": "application/sdp"})
            if response.status_code != 201:
                raise RuntimeError(f"WHEP refused: {response.status_code} {response.text[:300]}")
            self.location = response.headers["Location"]
            self.server_port = server_port(response.text)
            emu._call(lambda: setattr(emu.udp, "target", ("127.0.0.1", self.server_port)))
            answer = via(response.text, emu.udp_port)
            self.loop.run(self.pc.setRemoteDescription(RTCSessionDescription(answer, "answer")), timeout_s)
        except BaseException:
            self.close()
            raise

    async def _offer(self, teleop: bool) -> str:
        with only_host_addresses(LOOPBACK):
            self.pc = pc = RTCPeerConnection(RTCConfiguration(iceServers=[]))
            receiver = pc.addTransceiver("video", direction="recvonly").receiver
            count_rtp_payload(receiver, self._count)  # the payload bytes the link carried for video
            self.jitter = browser_jitter.install(receiver)  # frames to the decoder as a browser gives them
            if teleop:
                self.channel = pc.createDataChannel("teleop", ordered=False, maxRetransmits=0)
                self.channel.on("open", self.channel_open.set)
                self.channel.on("message", self._on_message)

            @pc.on("track")
            def _track(track) -> None:
                asyncio.ensure_future(self._read(track))

            await pc.setLocalDescription(await pc.createOffer())
        return filter_candidates(pc.localDescription.sdp, LOOPBACK)

    def _count(self, n: int) -> None:
        self._bytes += n

    async def _read(self, track) -> None:
        async for frame in decoded_frames(track):
            t = time.monotonic()
            now_ms = int(time.time() * 1000)
            size, self._bytes = self._bytes, 0
            # Off the loop: the RTP of the next frames keeps arriving while this one is read.
            rgb = await asyncio.get_running_loop().run_in_executor(
                None, functools.partial(frame.to_ndarray, format="rgb24"))
            stamp = timecode.read(rgb, now_ms=now_ms)
            self.samples.append((t, None if stamp is None else now_ms - stamp, size))
            self.sizes.append((t, f"{frame.width}x{frame.height}"))

    def _on_message(self, text) -> None:
        message = json.loads(text)
        if message.get("type") == "ping":  # answered at once, as the page does: the server measures the link
            self.channel.send(json.dumps({"pong": message["id"]}))
            return
        with self.cond:
            self.messages.append(message)
            self.cond.notify_all()

    def window(self, start: float, end: float) -> list[tuple[float, float | None, int]]:
        return [s for s in self.samples if start <= s[0] <= end]

    def size_shares(self, start: float, end: float) -> dict[str, float]:
        """The decoded frame sizes in [start, end], each with its share of the frames."""
        sizes = [s for t, s in self.sizes if start <= t <= end]
        return {s: round(sizes.count(s) / len(sizes), 2) for s in sorted(set(sizes))}

    def route(self) -> list[tuple[str, int, str, int]]:
        """(local host, port, remote host, port) of each nominated ICE pair on the client."""
        pairs = []
        for transceiver in self.pc.getTransceivers():
            connection = transceiver.receiver.transport.transport._connection  # aioice.Connection
            for pair in connection._nominated.values():
                pairs.append((pair.local_candidate.host, pair.local_candidate.port,
                              pair.remote_candidate.host, pair.remote_candidate.port))
        return pairs

    def close(self) -> None:
        if self.location:
            try:
                requests.delete(self.url + self.location, timeout=10)
            except requests.RequestException:
                pass
        if self.pc is not None and self.loop.running:
            try:
                self.loop.run(self.pc.close(), 10)
            except Exception:
                pass
        self.loop.stop()
        self.sink.close()


class ChannelSocket:
    """The data channel with the bits of bench/teleop.connect's socket the Stick uses: `heard`
    (the epoch the server last said, refusals counted) and a `send` of one teleop frame."""

    def __init__(self, whep: LinkWhep, heard_cls, timeout_s: float = 30.0):
        self.whep = whep
        if not whep.channel_open.wait(timeout_s):
            raise TimeoutError("the teleop data channel did not open")
        with whep.cond:
            if not whep.cond.wait_for(lambda: any(m.get("type") in ("hello", "error") for m in whep.messages),
                                      timeout_s):
                raise TimeoutError("no hello on the teleop data channel")
            hello = next(m for m in whep.messages if m.get("type") in ("hello", "error"))
        if hello["type"] != "hello":
            raise RuntimeError(f"the teleop data channel refused: {hello}")
        self.heard = heard_cls(hello["epoch"])
        self._seen = 0
        threading.Thread(target=self._follow, daemon=True).start()

    def _follow(self) -> None:
        while self.whep.loop.running:
            with self.whep.cond:
                self.whep.cond.wait(0.5)
                fresh, self._seen = self.whep.messages[self._seen:], len(self.whep.messages)
            for message in fresh:
                self.heard.note(message)

    def send(self, text: str) -> None:
        if not self.whep.loop.running or self.whep.channel.readyState != "open":
            raise OSError("the teleop data channel is closed")
        self.whep.loop.call_soon(self.whep.channel.send, text)
