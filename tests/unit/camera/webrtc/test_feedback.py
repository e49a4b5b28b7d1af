"""RTCP feedback on a sender: REMB kept; a NACK the sender cannot usefully answer becomes one keyframe."""

import asyncio
from types import SimpleNamespace

import pytest
from aiortc.rtp import (
    RTCP_PSFB_APP,
    RTCP_RTPFB_NACK,
    RTP_HISTORY_SIZE,
    RtcpPsfbPacket,
    RtcpRrPacket,
    RtcpRtpfbPacket,
    RtpPacket,
    pack_remb_fci,
)

from rover_web.camera.webrtc import feedback
from rover_web.camera.webrtc.silence import PROBE_S, SILENCE_S

SSRC = 1234
NOW_ABS = 5 << 18  # abs-send-time: 5 s


class Sender:
    """The bits of aiortc's RTCRtpSender that feedback.py touches."""

    def __init__(self):
        self._ssrc = SSRC
        self._RTCRtpSender__rtp_history = {}
        self.handled = []
        self.keyframes = 0
        self.encoded = 0

    async def _next_encoded_frame(self, codec):
        self.encoded += 1
        return f"frame {self.encoded}"

    async def _handle_rtcp_packet(self, packet):
        self.handled.append(packet)

    def _send_keyframe(self):
        self.keyframes += 1

    def sent(self, seq, seconds_ago):
        packet = RtpPacket(sequence_number=seq)
        packet.extensions.abs_send_time = (NOW_ABS - round(seconds_ago * (1 << 18))) & 0xFFFFFF
        self._RTCRtpSender__rtp_history[seq % RTP_HISTORY_SIZE] = packet


class Track:
    def __init__(self):
        self.taken = 0

    async def recv(self):
        self.taken += 1


class Clock:
    t = 100.0

    def __call__(self):
        return self.t


@pytest.fixture
def rig(monkeypatch):
    monkeypatch.setattr(feedback, "_abs_send_time_now", lambda: NOW_ABS)
    sender, clock = Sender(), Clock()
    session = SimpleNamespace(sender=sender, track=Track(), remb_bps=None, loss_keyframes=0, encoder_restarts=0,
                              link_share=1.0)
    feedback.tap_rtcp(session, clock=clock)
    return session, sender, clock


def nack(*lost):
    return RtcpRtpfbPacket(fmt=RTCP_RTPFB_NACK, ssrc=1, media_ssrc=SSRC, lost=list(lost))


def feed(session, packet):
    asyncio.run(session.sender._handle_rtcp_packet(packet))


def remb(estimate):
    return RtcpPsfbPacket(fmt=RTCP_PSFB_APP, ssrc=1, media_ssrc=0, fci=pack_remb_fci(estimate, [SSRC]))


def test_remb_is_kept_unclamped_and_only_we_set_the_encoder(rig):
    session, sender, _ = rig
    feed(session, remb(90_000))
    assert session.remb_bps == 90_000
    # aiortc's own handler would give the encoder the whole estimate, racing the encoding thread.
    assert sender.handled == []


def test_the_encoder_gets_the_link_share_of_the_estimate_in_steps(rig):
    from aiortc.codecs.vpx import Vp8Encoder

    session, sender, clock = rig
    session.link_share = 0.75
    encoder = sender._RTCRtpSender__encoder = Vp8Encoder()
    assert encoder.target_bitrate == 500_000  # aiortc's own start
    feed(session, remb(1_000_000))
    assert encoder.target_bitrate == 750_000 and session.encoder_restarts == 1  # a slow start climbs at once
    # A few per cent either way, as nearly every REMB moves: the encoder (and its keyframe-free stream) stays.
    for estimate in (1_040_000, 970_000, 1_080_000, 1_010_000):
        clock.t += 0.1
        feed(session, remb(estimate))
        assert session.remb_bps == estimate and encoder.target_bitrate == 750_000
    # The link pushed back: down at once.
    clock.t += 0.1
    feed(session, remb(400_000))
    assert encoder.target_bitrate == 300_000 and session.encoder_restarts == 2
    # It recovers: up only once the estimate has stayed higher for UP_HOLD_S.
    feed(session, remb(800_000))
    assert encoder.target_bitrate == 300_000
    clock.t += 2.5
    feed(session, remb(800_000))
    assert encoder.target_bitrate == 600_000 and session.encoder_restarts == 3
    # Below aiortc's own floor (250 kbit/s), down to ours.
    clock.t += 0.5
    feed(session, remb(120_000))
    assert encoder.target_bitrate == feedback.ENCODER_FLOOR_BPS < 250_000


def test_a_nack_of_recent_packets_is_resent_by_aiortc(rig):
    session, sender, _ = rig
    sender.sent(10, 0.2)
    sender.sent(11, 0.2)
    feed(session, nack(10, 11))
    assert len(sender.handled) == 1 and sender.keyframes == 0


@pytest.mark.parametrize("why", ["gone from the history", "too old"])
def test_a_nack_naming_a_hopeless_packet_resends_nothing_and_asks_for_a_keyframe(rig, why):
    session, sender, _ = rig
    sender.sent(11, 0.2)
    if why == "too old":
        sender.sent(10, feedback.MAX_RESEND_AGE_S + 0.5)
    else:
        sender.sent(10 + RTP_HISTORY_SIZE, 0.1)  # 10's place in the history, taken by a newer packet
    feed(session, nack(10, 11))
    assert sender.handled == []
    assert sender.keyframes == 1 and session.loss_keyframes == 1


def test_repeated_hopeless_nacks_make_one_keyframe_per_interval(rig):
    session, sender, clock = rig
    for _ in range(5):
        feed(session, nack(10))
        clock.t += 0.1
    assert sender.keyframes == 1
    clock.t += feedback.KEYFRAME_MIN_INTERVAL_S
    feed(session, nack(10))
    assert sender.keyframes == 2 and sender.handled == []


def next_frame(session):
    return asyncio.run(session.sender._next_encoded_frame(None))


def test_while_the_browser_is_quiet_frames_are_taken_but_not_encoded_and_feedback_resumes_them(rig):
    session, sender, clock = rig
    assert next_frame(session) == "frame 1"  # no feedback yet: the stream is starting
    feed(session, remb(400_000))
    clock.t += SILENCE_S + 0.1  # an outage: nothing from the browser since
    assert next_frame(session) == "frame 2"  # one goes, for a browser that answers only media
    for _ in range(5):
        clock.t += 0.05
        assert next_frame(session) is None
    assert session.track.taken == 5 and session.silence.held == 5  # at the viewer's pace, the newest after
    clock.t += PROBE_S
    assert next_frame(session) == "frame 3"
    feed(session, RtcpRrPacket(ssrc=1, reports=[]))  # any report
    assert [next_frame(session) for _ in range(3)] == ["frame 4", "frame 5", "frame 6"]
    assert sender.encoded == 6

