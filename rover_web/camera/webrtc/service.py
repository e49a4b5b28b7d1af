"""WebRtcService: one robot's WHEP sessions, each a peer connection that sends the camera and may
carry the teleop data channel.

Lifecycle of a session (all peer-connection work on the LoopThread):
- `open` (a request thread): the query is checked as /stream's (CameraStreams.key_for), a viewer
  place (ROVER_WEB_WEBRTC_MAX_VIEWERS, at most ROVER_WEB_WEBRTC_VIEWERS_PER_CLIENT of them per
  client) is taken with the slot of ROVER_WEB_MAX_STREAMS the route took for the client
  (web/streams.py: its share, and the reserve left for driving), the shared frame producer is
  leased against the client's share of encodings, then the offer is answered on the loop
  (candidates gathered before answering: no trickle). Any failure gives all of it back before the
  error is answered.
- it ends on DELETE, when its peer connection fails or closes, when it has not been connected for
  ROVER_WEB_WEBRTC_IDLE_TIMEOUT_S (never connected, or lost), when its user is revoked
  (`close_sessions_of`), and at shutdown; `_end` gives everything back exactly once.

The user and whether they may drive are read when the session is made and kept on it: the teleop
channel is refused to a session whose user was not an operator then, and the lead's revocation
hook ends the sessions of a user whose rights change.
"""

from __future__ import annotations

import asyncio
import json
import logging
import secrets
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rover_web.camera import msgs as camera_msgs
from rover_web.camera.service import CameraStreams, CannotSubscribe, Unavailable
from rover_web.camera.stream import FrameProducer, StreamKey
from rover_web.config import ConfigError
from rover_web.core.leases import Closed, Full, Leases, ShareUsed
from rover_web.core.state import Rover
from rover_web.core.streams import StreamSlot
from rover_web.web.api_messages import explain, request_catalogues, text_of
from rover_web.web.validate import InvalidInput

from . import frames
from .adapt import AdaptPolicy
from .feedback import tap_rtcp
from .ice import (
    filter_candidates,
    host_addresses,
    only_host_addresses,
    parse_ice_server,
    screen_remote_candidates,
    without_mdns,
)
from .loop import LoopStopped, LoopThread

if TYPE_CHECKING:
    from .track import CameraTrack

# aiortc, aioice and av (FFmpeg) are imported on the first offer, not at start: together about
# 45 MB of a server's resident memory that a robot nobody watches over WebRTC does not need.

log = logging.getLogger(__name__)

# How long a request thread waits for the loop to answer an offer (gathering included).
NEGOTIATE_TIMEOUT_S = 10.0
CLOSE_TIMEOUT_S = 5.0
WATCH_PERIOD_S = 0.5
MAX_OFFER_CHARS = 64 * 1024


class NoVideo(InvalidInput):
    pass


@dataclass(eq=False)
class WhepSession:
    id: str
    user: str | None
    role: str | None
    may_operate: bool
    key: StreamKey
    slot: StreamSlot
    created: float = field(default_factory=time.monotonic)
    producer: FrameProducer | None = None
    pc: Any = None
    track: CameraTrack | None = None
    sender: Any = None
    teleop: Any = None  # rover_web.teleop.datachannel.TeleopChannel once the channel opened
    state: str = "new"
    last_connected: float | None = None
    ended: str | None = None  # why it ended
    catalogues: tuple | None = None  # the offer's language, for the data channel's error frames
    remb_bps: int | None = None  # the browser's latest estimate, unclamped
    link_share: float = 1.0  # of that estimate, what the video may use (ROVER_WEB_WEBRTC_LINK_SHARE)
    loss_keyframes: int = 0  # keyframes sent instead of resending what could not help (feedback.py)
    encoder_restarts: int = 0  # bitrate changes aiortc made a new encoder (and so a keyframe) for
    silence: Any = None  # silence.Silence: frames held while the browser sends no feedback
    revocation: Any = None  # its credential's registration (auth/revocation.py), cancelled when it ends

    @property
    def client(self) -> str | None:
        """Whose shares it counts against (web/streams.py's client_key), as its stream slot says."""
        return self.slot.client

    def encoder_bitrate(self) -> int | None:
        # aiortc sets its encoder's target from each REMB packet, clamped (250 kbit/s to 1.5 Mbit/s
        # for VP8); the encoder is the sender's own, private attribute (aiortc is pinned).
        encoder = getattr(self.sender, "_RTCRtpSender__encoder", None)
        return getattr(encoder, "target_bitrate", None)

    def target_bitrate(self) -> int | None:
        """What the link allows, for the adaptation: the browser's whole estimate when one came
        (aiortc's encoder cannot go below its floor, so the estimate says more; with only the
        encoder's share of it, wifi-edge stepped down to 18 fps where it carries 30), else the
        encoder's target."""
        return self.remb_bps if self.remb_bps is not None else self.encoder_bitrate()

    def describe(self) -> dict:
        track = self.track
        out = track.output if track else None
        return {"user": self.user, "topic": self.key.topic, "state": self.state,
                "frames_sent": track.frames_sent if track else 0,
                "level": out.level if out else None, "width": out.width if out else None,
                "height": out.height if out else None, "fps": out.fps if out else None,
                "target_bps": self.encoder_bitrate(), "remb_bps": self.remb_bps,
                "loss_keyframes": self.loss_keyframes, "encoder_restarts": self.encoder_restarts,
                "frames_held": self.silence.held if self.silence else 0,
                "teleop": self.teleop is not None and not self.teleop.closed,
                "source_hz": self.producer.arrivals.snapshot(stale_after_s=2.0)["rate_hz"] if self.producer else None,
                "age_s": round(time.monotonic() - self.created, 1)}


def _check_fingerprints(offer: str) -> None:
    """aiortc takes an offer whose DTLS fingerprints it cannot check, then fails the handshake
    later; say so now, as a 400."""
    from aiortc.rtcdtlstransport import X509_DIGEST_ALGORITHMS
    from aiortc.sdp import SessionDescription

    for media in SessionDescription.parse(offer).media:
        if not any(f.algorithm in X509_DIGEST_ALGORITHMS for f in media.dtls.fingerprints):
            raise InvalidInput("the offer's %(kind)s section has no DTLS fingerprint this server can check "
                               "(%(x509_digest_algorithms)s)", "bad_sdp",
                               kind=media.kind, x509_digest_algorithms=', '.join(X509_DIGEST_ALGORITHMS))


class WebRtcService:
    def __init__(self, rover: Rover, loop: LoopThread, camera: CameraStreams):
        config = rover.config
        self.rover = rover
        self.loop = loop
        self.camera = camera
        self.max_viewers = config["ROVER_WEB_WEBRTC_MAX_VIEWERS"]
        self.viewers_per_client = config["ROVER_WEB_WEBRTC_VIEWERS_PER_CLIENT"]
        self.producers_per_client = config["ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT"]
        self.idle_timeout_s = config["ROVER_WEB_WEBRTC_IDLE_TIMEOUT_S"]
        self.max_fps = config["ROVER_WEB_WEBRTC_MAX_FPS"]
        self.link_share = config["ROVER_WEB_WEBRTC_LINK_SHARE"]
        self.host_addresses = host_addresses(config)
        try:
            self.ice_servers = [parse_ice_server(s) for s in config["ROVER_WEB_WEBRTC_ICE_SERVERS"]]
        except ValueError as exc:
            raise ConfigError(f"ROVER_WEB_WEBRTC_ICE_SERVERS: {exc}") from None
        self.producers: Leases[FrameProducer] = Leases(self._open_producer, self._close_producer,
                                                       config["ROVER_WEB_CAMERA_IDLE_TIMEOUT_S"],
                                                       max_keys=config["ROVER_WEB_CAMERA_MAX_PRODUCERS"])
        # Each viewer's track waits for frames in this pool (and builds its video frames here).
        self._frames = ThreadPoolExecutor(max_workers=2 * self.max_viewers + 1, thread_name_prefix="webrtc-frames")
        self._teleop = ThreadPoolExecutor(max_workers=1, thread_name_prefix="webrtc-teleop")
        self._sessions: dict[str, WhepSession] = {}
        self._lock = threading.Lock()
        self._closed = False
        self._watch: Any = None

    # --- producers: the camera's subscription and newest-message store, converting for video ---

    def _open_producer(self, key: StreamKey) -> FrameProducer:
        max_pixels = self.camera.max_output_pixels

        def convert(raw) -> frames.Picture:
            try:
                return frames.to_picture(raw, key.width, key.height, max_pixels)
            except frames.FrameError as exc:
                return frames.error_picture(str(exc), exc.code, key.width, key.height, max_pixels)
            except Exception:  # a bug, not bad data: keep the stream alive and say where to look
                log.exception("converting a frame from %s failed", key.topic)
                return frames.error_picture("the server could not convert this frame; see its log",
                                            "internal_error", key.width, key.height, max_pixels)

        producer = FrameProducer(key, convert)  # type: ignore[arg-type]  # Picture duck-types Jpeg
        read = camera_msgs.frame_reader(key.msg_type)
        producer.subscription = self.rover.runtime.subscribe(
            key.msg_type, key.topic, lambda msg: producer.put(read(msg)), qos=key.qos, track=False)
        return producer

    def _close_producer(self, producer: FrameProducer) -> None:
        producer.close()
        if self.rover.runtime.running:
            self.rover.runtime.destroy(producer.subscription)

    # --- life ---

    def start(self) -> None:
        self._watch = self.loop.submit(self._watch_sessions())

    async def _watch_sessions(self) -> None:
        running = asyncio.get_running_loop()
        while True:
            await asyncio.sleep(WATCH_PERIOD_S)
            now = time.monotonic()
            for session in self.sessions():
                since = session.last_connected if session.state != "connected" and session.last_connected \
                    else session.created
                if session.state != "connected" and now - since > self.idle_timeout_s:
                    await self._end(session, "idle")
            await running.run_in_executor(self._frames, self.producers.reap)

    def close(self) -> None:
        """Shutdown: every session ended, producers and pools closed. Idempotent."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
        if self.loop.running:
            try:
                self.loop.run(self._end_all("shutdown"), CLOSE_TIMEOUT_S)
            except (TimeoutError, LoopStopped):
                log.warning("WebRTC sessions did not all close within %.1f s", CLOSE_TIMEOUT_S)
        if self._watch is not None:
            self._watch.cancel()
        self.producers.close_all()
        for session in self.sessions():  # the loop was gone: give back what it could not
            self._give_back(session)
        self._frames.shutdown(wait=True, cancel_futures=True)
        self._teleop.shutdown(wait=True, cancel_futures=True)

    async def _end_all(self, reason: str) -> None:
        await asyncio.gather(*(self._end(s, reason) for s in self.sessions()), return_exceptions=True)

    # --- requests ---

    def sessions(self) -> list[WhepSession]:
        with self._lock:
            return list(self._sessions.values())

    def describe(self) -> dict:
        return {"max_viewers": self.max_viewers, "sessions": [s.describe() for s in self.sessions()]}

    def open(self, args, offer: str, *, user: str | None, role: str | None, may_operate: bool,
             slot: StreamSlot) -> tuple[str, str]:
        """Answer a WHEP offer: (session id, SDP answer). InvalidInput, UnknownTopic, Unavailable,
        CannotSubscribe as CameraStreams raises them. `slot` is the request's slot of the stream cap,
        taken for its client in the request thread (web/streams.py); the session owns it from now on,
        and gives it back when it ends, or at once when it cannot be made."""
        key = self.camera.key_for(args)
        if len(offer) > MAX_OFFER_CHARS:
            raise InvalidInput("the offer is longer than %(max_offer_chars)s characters", "bad_sdp",
                               max_offer_chars=MAX_OFFER_CHARS)
        if not offer.lstrip().startswith("v=0"):
            raise InvalidInput("the body is not an SDP offer (it must start with v=0)", "bad_sdp")
        if "\nm=video " not in offer.replace("\r\n", "\n"):
            raise NoVideo("the offer has no video media section: add a recvonly video transceiver", "no_video")
        # An offer left with no candidate is still answered: the browser's own checks reach ours and
        # are answered as peer-reflexive, so nothing is sent to a place the offer named.
        offer, _kept, _dropped = screen_remote_candidates(offer)
        session = self._reserve(key, user, role, may_operate, slot)
        try:
            client = session.client
            try:
                session.producer = self.producers.acquire(key, client, None if client is None
                                                          else self.producers_per_client)
            except Closed:
                raise Unavailable(explain("the server is shutting down"), "shutting_down") from None
            except ShareUsed as exc:
                raise Unavailable(explain("%(why)s different WebRTC camera streams "
                                          "(ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT); close one first", why=text_of(exc)),
                                  "too_many_producers") from None
            except Full:
                raise Unavailable(explain("%(count)s different WebRTC camera streams are converted already "
                                          "(ROVER_WEB_CAMERA_MAX_PRODUCERS); view one of them",
                                          count=len(self.producers)), "too_many_producers") from None
            except Exception as exc:
                log.exception("cannot subscribe to %s", key.topic)
                raise CannotSubscribe(explain("cannot subscribe to %(topic)s: %(why)s", topic=key.topic,
                                              why=text_of(exc)), "cannot_subscribe") from None
            try:
                answer = self.loop.run(self._negotiate(session, offer), NEGOTIATE_TIMEOUT_S)
            except LoopStopped:
                raise Unavailable(explain("the server is shutting down"), "shutting_down") from None
            except TimeoutError:
                raise Unavailable(explain("the WebRTC loop did not answer the offer in time"),
                                  "webrtc_timeout") from None
        except BaseException:
            self._abandon(session)
            raise
        return session.id, answer

    def _reserve(self, key: StreamKey, user: str | None, role: str | None, may_operate: bool,
                 slot: StreamSlot) -> WhepSession:
        try:
            with self._lock:
                if self._closed:
                    raise Unavailable(explain("the server is shutting down"), "shutting_down")
                if len(self._sessions) >= self.max_viewers:
                    raise Unavailable(explain("%(count)s WebRTC viewers are connected already "
                                              "(ROVER_WEB_WEBRTC_MAX_VIEWERS); watch the MJPEG stream instead: GET "
                                              "/stream?topic=%(topic)s",
                                              count=len(self._sessions), topic=key.topic), "too_many_webrtc_viewers")
                # Each session has its own encoder and a place of few: one client must leave the
                # others some, whatever its share of the much larger stream cap.
                held = 0 if slot.client is None else sum(s.client == slot.client for s in self._sessions.values())
                if held >= self.viewers_per_client:
                    raise Unavailable(explain("this client holds %(held)s WebRTC viewer places already, its share "
                                              "(ROVER_WEB_WEBRTC_VIEWERS_PER_CLIENT); close one, or watch the "
                                              "MJPEG stream instead: GET /stream?topic=%(topic)s",
                                              held=held, topic=key.topic), "too_many_webrtc_viewers")
                session = WhepSession(secrets.token_urlsafe(16), user, role, may_operate, key, slot,
                                      catalogues=request_catalogues())
                self._sessions[session.id] = session
                return session
        except BaseException:
            slot.release()
            raise

    def _abandon(self, session: WhepSession) -> None:
        """An offer that failed: its peer connection (if any) closed on the loop, the rest given back."""
        if session.pc is not None and self.loop.running:
            try:
                self.loop.run(self._end(session, "refused"), CLOSE_TIMEOUT_S)
                return
            except (TimeoutError, LoopStopped):
                log.warning("closing a refused WebRTC offer's peer connection timed out")
        self._give_back(session)

    async def _negotiate(self, session: WhepSession, offer: str) -> str:
        from aiortc import RTCConfiguration, RTCIceServer, RTCPeerConnection, RTCSessionDescription

        from .track import CameraTrack

        config = RTCConfiguration(iceServers=[RTCIceServer(**s) for s in self.ice_servers])  # [] : no STUN
        with only_host_addresses(self.host_addresses):
            pc = RTCPeerConnection(config)
            session.pc = pc

            @pc.on("connectionstatechange")
            async def _state_changed() -> None:
                session.state = pc.connectionState
                if pc.connectionState == "connected":
                    session.last_connected = time.monotonic()
                elif pc.connectionState in ("failed", "closed"):
                    await self._end(session, pc.connectionState)
                elif session.last_connected is not None:
                    session.last_connected = time.monotonic()  # lost now: the idle clock starts

            @pc.on("datachannel")
            def _channel(channel) -> None:
                self._on_datachannel(session, channel)

            try:
                await pc.setRemoteDescription(RTCSessionDescription(sdp=without_mdns(offer), type="offer"))
            except Exception as exc:  # aiortc raises ValueError, KeyError, IndexError... for bad SDP
                raise InvalidInput("the SDP offer could not be used: %(value)s",
                                   "bad_sdp", value=str(exc)[:200] or type(exc).__name__) from None
            _check_fingerprints(offer)
            video = [t for t in pc.getTransceivers() if t.kind == "video"]
            if not video or video[0].direction not in ("recvonly", "sendrecv"):
                raise NoVideo("the offer's video section must be recvonly (or sendrecv)", "no_video")
            track = CameraTrack(session.producer, self._frames, AdaptPolicy(self.max_fps), session.target_bitrate)
            session.track = track
            video[0].direction = "sendonly"
            session.sender = pc.addTrack(track)
            session.link_share = self.link_share
            tap_rtcp(session)
            try:
                answer = await pc.createAnswer()
                await pc.setLocalDescription(answer)
            except Exception as exc:
                raise InvalidInput("no answer can be made to this offer: %(why)s", "bad_sdp",
                                   why=str(exc)[:200]) from None
        return filter_candidates(pc.localDescription.sdp, self.host_addresses)

    def _on_datachannel(self, session: WhepSession, channel) -> None:
        from rover_web.teleop.datachannel import LABEL, TeleopChannel
        from rover_web.teleop.service import TeleopService

        if channel.label != LABEL or session.ended:
            channel.close()
            return
        if not session.may_operate or session.teleop is not None:
            why = (explain("driving needs the operator role; %(name)s is a %(role)s", name=session.user,
                           role=session.role) if not session.may_operate
                   else explain("this session has a teleop channel already"))
            channel.send(json.dumps({"type": "error", "error": "forbidden", "status": 403,
                                     "message": why.translated(session.catalogues)}))
            channel.close()
            return
        teleop = self.rover.feature(TeleopService)
        glue = TeleopChannel(channel, teleop.controller, session.user, teleop.hello(), teleop.max_frame_bytes,
                             call_soon=self.loop.call_soon, call_later=self.loop.loop.call_later, pool=self._teleop)
        glue.session.catalogues = session.catalogues
        session.teleop = glue
        channel.on("message", glue.on_message)
        channel.on("close", glue.close)

    def end(self, session_id: str, user: str | None = None, *, admin: bool = False) -> bool:
        """DELETE: False when no such session (or it is someone else's and the caller is no admin)."""
        with self._lock:
            session = self._sessions.get(session_id)
        if session is None or (user is not None and session.user not in (None, user) and not admin):
            return False
        self._run_end(session, "deleted")
        return True

    def close_sessions_of(self, user_name: str) -> int:
        """End every session made by `user_name` (revoked, removed, or role changed); how many."""
        found = [s for s in self.sessions() if s.user == user_name]
        for session in found:
            self._run_end(session, "revoked")
        return len(found)

    def watch(self, session_id: str, registration) -> None:
        """Keep the session's revocation registration; cancelled at once if the session already ended."""
        with self._lock:
            session = self._sessions.get(session_id)
            if session is not None:
                session.revocation = registration
        if session is None:
            registration.cancel()

    def revoke(self, session_id: str, reason: str) -> None:
        """Its credential ended (token revoked, user removed, role or password changed, signed out):
        end the session on the loop without waiting, as a revocation callback must not block. The
        teleop channel, if it drives, stops the robot first (`_end`)."""
        with self._lock:
            session = self._sessions.get(session_id)
        if session is None:
            return
        log.info("WebRTC session of %s ends: %s", session.user, reason)
        try:
            self.loop.submit(self._end(session, "revoked"))
        except LoopStopped:
            self._give_back(session)

    def _run_end(self, session: WhepSession, reason: str) -> None:
        try:
            self.loop.run(self._end(session, reason), CLOSE_TIMEOUT_S)
        except (TimeoutError, LoopStopped):
            log.warning("ending WebRTC session for %s timed out", session.user)
            self._give_back(session)

    async def _end(self, session: WhepSession, reason: str) -> None:
        if session.ended:
            return
        session.ended = reason
        if session.teleop is not None:
            session.teleop.close()  # zero first, if it held control
        if session.track is not None:
            session.track.stop()
        pc = session.pc
        if pc is not None:
            try:
                await pc.close()
            except Exception:
                log.exception("closing a WebRTC peer connection failed")
        session.state = "closed"
        self._give_back(session)

    def _give_back(self, session: WhepSession) -> None:
        with self._lock:
            if self._sessions.pop(session.id, None) is None:
                return
        session.ended = session.ended or "closed"
        if session.revocation is not None:
            session.revocation.cancel()
        if session.producer is not None:
            self.producers.release(session.key, session.client)
        session.slot.release()

