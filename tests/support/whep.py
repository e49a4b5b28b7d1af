"""A WHEP client for tests and benches: an aiortc peer in this process, on 127.0.0.1 only.

It offers a recvonly video section (and, if asked, the `teleop` data channel as browsers open it:
unordered, no retransmits), gathers host candidates on 127.0.0.1 alone (rover_web's own
`only_host_addresses`, and the offer filtered as a second guard), POSTs the offer and sets the
answer. Frames are decoded as they come (`frames`: (arrival monotonic, width, height)); data
channel messages land in `messages`. `nominated()` names the ICE pair actually used, so a test
fails if any address but 127.0.0.1 carried the media.
"""

from __future__ import annotations

import asyncio
import json
import threading
import time
from collections import deque

import requests
from aiortc import RTCConfiguration, RTCPeerConnection, RTCSessionDescription
from aiortc.mediastreams import MediaStreamError

from rover_web.camera.webrtc.ice import candidates, filter_candidates, only_host_addresses
from rover_web.camera.webrtc.loop import LoopThread

LOOPBACK = ["127.0.0.1"]


class WhepRefused(Exception):
    def __init__(self, response: requests.Response):
        super().__init__(f"{response.status_code} {response.text[:300]}")
        self.response = response
        self.status = response.status_code
        self.body = response.json() if response.headers.get("Content-Type", "").startswith("application/json") else {}


class WhepClient:
    def __init__(self, base_url: str, query: str, *, teleop: bool = False, headers: dict | None = None,
                 video: bool = True, timeout_s: float = 20.0):
        self.base_url = base_url
        self.headers = dict(headers or {})
        self.loop = LoopThread("whep-client")
        self.loop.start()
        self.frames: deque = deque(maxlen=10000)
        self.messages: deque = deque(maxlen=10000)
        self.channel = None
        self.channel_open = threading.Event()
        self.channel_closed = threading.Event()
        self.answer_pings = True
        self._cond = threading.Condition()
        self.pc = None
        self.location = None
        self._reader = None
        try:
            offer = self.loop.run(self._offer(teleop, video), timeout_s)
            response = requests.post(f"{base_url}/api/camera/whep?{query}", data=offer, timeout=timeout_s,
                                     headers={"Content-Type": "application/sdp", **self.headers})
            if response.status_code != 201:
                raise WhepRefused(response)
            self.location = response.headers["Location"]
            self.answer = response.text
            self.loop.run(self.pc.setRemoteDescription(RTCSessionDescription(self.answer, "answer")), timeout_s)
        except BaseException:
            self.close()
            raise

    async def _offer(self, teleop: bool, video: bool) -> str:
        with only_host_addresses(LOOPBACK):
            self.pc = pc = RTCPeerConnection(RTCConfiguration(iceServers=[]))
            if video:
                pc.addTransceiver("video", direction="recvonly")
            if teleop:
                self.channel = pc.createDataChannel("teleop", ordered=False, maxRetransmits=0)
                self.channel.on("open", self.channel_open.set)
                self.channel.on("close", self._channel_closed)
                self.channel.on("message", self._on_message)

            @pc.on("track")
            def _track(track) -> None:
                self._reader = asyncio.ensure_future(self._read(track))

            await pc.setLocalDescription(await pc.createOffer())
        return filter_candidates(pc.localDescription.sdp, LOOPBACK)

    def _channel_closed(self) -> None:
        self.channel_closed.set()
        with self._cond:
            self._cond.notify_all()

    def _on_message(self, text) -> None:
        message = json.loads(text)
        if message.get("type") == "ping" and self.answer_pings:  # as the page does: the server's round trip
            self.channel.send(json.dumps({"pong": message["id"]}))
        message["t"] = time.monotonic()
        with self._cond:
            self.messages.append(message)
            self._cond.notify_all()

    async def _read(self, track) -> None:
        while True:
            try:
                frame = await track.recv()
            except MediaStreamError:
                return
            self.frames.append((time.monotonic(), frame.width, frame.height))

    # --- test side ---

    @property
    def connection_state(self) -> str:
        return self.pc.connectionState if self.pc else "closed"

    def nominated(self) -> list[tuple[str, str]]:
        """(local, remote) host of each nominated ICE pair."""
        pairs = []
        for transceiver in self.pc.getTransceivers():
            connection = transceiver.receiver.transport.transport._connection  # aioice.Connection
            for pair in connection._nominated.values():
                pairs.append((pair.local_candidate.host, pair.remote_candidate.host))
        return pairs

    def answer_candidates(self) -> list[tuple[str, str]]:
        return candidates(self.answer)

    def send(self, message: dict | str) -> None:
        text = message if isinstance(message, str) else json.dumps(message)
        self.loop.call_soon(self.channel.send, text)

    def delete(self) -> requests.Response:
        return requests.delete(self.base_url + self.location, headers=self.headers, timeout=10)

    def close(self) -> None:
        if self.pc is not None and self.loop.running:
            try:
                self.loop.run(self.pc.close(), 10)
            except Exception:
                pass
        self.loop.stop()


class ChannelTeleop:
    """The `teleop` data channel of a WhepClient with tests/support/teleop_support.TeleopClient's
    interface, so one test body drives over either transport."""

    def __init__(self, client: WhepClient, timeout_s: float = 15.0):
        self.client = client
        if not client.channel_open.wait(timeout_s):
            raise TimeoutError("the teleop data channel did not open")
        self.closed = client.channel_closed
        self.hello = self.wait_for(lambda m: m["type"] in ("hello", "error"))

    @property
    def messages(self) -> list[dict]:
        with self.client._cond:
            return list(self.client.messages)

    @property
    def epoch(self) -> int:
        for message in reversed(self.messages):
            if message["type"] in ("hello", "state"):
                return message["epoch"]
        return 0

    def send(self, frame) -> None:
        self.client.send(frame if isinstance(frame, str) else json.dumps(frame, allow_nan=True))

    def drive(self, linear: float, angular: float = 0.0, epoch: int | None = None, **extra) -> float:
        frame = {"linear": linear, "angular": angular, "epoch": self.epoch if epoch is None else epoch, **extra}
        t = time.monotonic()
        self.send(frame)
        return t

    def wait_for(self, predicate, timeout: float = 10.0) -> dict:
        deadline = time.monotonic() + timeout
        seen = 0
        cond = self.client._cond
        with cond:
            while True:
                messages = list(self.client.messages)
                for message in messages[seen:]:
                    if predicate(message):
                        return message
                seen = len(messages)
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self.closed.is_set():
                    raise TimeoutError(f"no matching message within {timeout} s: {messages[-5:]}")
                cond.wait(remaining)

    def errors(self, code: str | None = None) -> list[dict]:
        return [m for m in self.messages if m["type"] == "error" and (code is None or m["error"] == code)]

    def wait_errors(self, count: int, timeout: float = 5.0) -> list[dict]:
        with self.client._cond:
            if not self.client._cond.wait_for(lambda: len(self.errors()) >= count, timeout):
                raise TimeoutError(f"{len(self.errors())} error frames, expected {count}")
        return self.errors()

    def close(self) -> None:
        self.client.close()
