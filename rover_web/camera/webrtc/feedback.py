"""What the browser's RTCP feedback does to one session's sender, beyond what aiortc does with it.

- REMB: the browser's bitrate estimate is kept unclamped (`session.remb_bps`) for the adaptation
  (adapt.py), and the encoder is given only `session.link_share` of it, in steps (bitrate.py).
  aiortc gives the encoder the whole estimate: the video then fills the link, and what a stall
  held back (the video's own frames, the e-stop's answer, events) drains only as fast as the
  video leaves room. The share leaves that room. It stays above 2/3: the browser never estimates
  more than 1.5 × what arrives, so with less the estimate, and the video with it, sinks to the
  floor however good the link (0.5, or a fixed 250 kbit/s reserve, kept wifi-edge at 150 kbit/s).
  aiortc's VP8 encoder will not go below 250 kbit/s, half a 0.5 Mbit/s radio; ENCODER_FLOOR_BPS
  lowers that floor (BENCHMARKS.md, 2026-11-27).
- NACK of packets that cannot help any more: aiortc resends whatever the NACK names that is in its
  last 128 packets. After an outage (the radio's 3 s) the browser names every packet it missed:
  over a hundred, seconds old, a burst of ~150 kB that on a 500 kbit/s radio with a 64 kB buffer
  clogs the link for seconds, loses part of itself and delays the fresh frames behind it, while
  the picture still cannot be decoded (a packet older than the history is gone, and every VP8
  frame needs the one before). When a NACK names a packet the sender no longer has, or one sent
  more than MAX_RESEND_AGE_S ago, nothing is resent and the next frame is a keyframe instead (at
  most one such keyframe per KEYFRAME_MIN_INTERVAL_S: the browser repeats its NACKs). The browser
  then shows a fresh picture about a round trip after the link is back.
- Silence: any RTCP packet tells silence.py the browser hears us; while it does not, the sender's
  private _next_encoded_frame takes frames without encoding them.
These wrap the sender's private _handle_rtcp_packet and _next_encoded_frame (aiortc is pinned).
"""

from __future__ import annotations

import time
from typing import Any

from .bitrate import EncoderBitrate
from .silence import Silence

# A resent packet older than this arrives after the browser's jitter buffer has given its frame
# up (libwebrtc: a few NACK rounds); the radio's deep buffer alone holds about a second.
MAX_RESEND_AGE_S = 1.5
KEYFRAME_MIN_INTERVAL_S = 1.0
ENCODER_FLOOR_BPS = 100_000  # aiortc's VP8 floor is 250 kbit/s; the adaptation steps fps and size down below
_ABS_SEND_TIME_HZ = 1 << 18  # RTP abs-send-time: 6.18 fixed-point seconds, 24 bits


def _abs_send_time_now() -> int:
    from aiortc import clock

    return (clock.current_ntp_time() >> 14) & 0xFFFFFF


def can_resend(sender: Any, seq: int, now_abs: int) -> bool:
    """The packet is in the sender's history, sent at most MAX_RESEND_AGE_S ago."""
    from aiortc.rtp import RTP_HISTORY_SIZE

    packet = sender._RTCRtpSender__rtp_history.get(seq % RTP_HISTORY_SIZE)
    if packet is None or packet.sequence_number != seq:
        return False
    sent = packet.extensions.abs_send_time
    return sent is None or ((now_abs - sent) & 0xFFFFFF) / _ABS_SEND_TIME_HZ <= MAX_RESEND_AGE_S


def tap_rtcp(session: Any, clock=time.monotonic) -> None:
    """On a WhepSession whose sender is made: REMB kept, hopeless NACKs turned into a keyframe."""
    import aiortc.codecs.vpx as vpx
    from aiortc.rtp import RTCP_PSFB_APP, RTCP_RTPFB_NACK, RtcpPsfbPacket, RtcpRtpfbPacket, unpack_remb_fci

    vpx.MIN_BITRATE = min(vpx.MIN_BITRATE, ENCODER_FLOOR_BPS)  # read by the encoder's setter each time
    sender = session.sender
    handle = sender._handle_rtcp_packet  # called per RTCP packet by the DTLS transport's router
    last_keyframe = -float("inf")
    steps = EncoderBitrate(vpx.DEFAULT_BITRATE, clock=clock)  # where aiortc's encoder starts
    quiet = session.silence = Silence(clock)

    async def _handle(packet) -> None:
        nonlocal last_keyframe
        quiet.heard()
        if isinstance(packet, RtcpPsfbPacket) and packet.fmt == RTCP_PSFB_APP:
            try:
                bitrate, ssrcs = unpack_remb_fci(packet.fci)
            except ValueError:
                bitrate, ssrcs = None, ()
            if bitrate is not None and sender._ssrc in ssrcs:
                # Not passed on: all aiortc does with a REMB is give the encoder the whole estimate,
                # and the encoder runs in a pool thread that could read it before ours replaced it.
                session.remb_bps = bitrate
                encoder = getattr(sender, "_RTCRtpSender__encoder", None)
                if encoder is not None and hasattr(encoder, "target_bitrate"):
                    before = encoder.target_bitrate
                    wanted = int(bitrate * session.link_share)
                    encoder.target_bitrate = steps.update(wanted)  # clamped by the encoder
                    if abs(encoder.target_bitrate - before) > 0.1 * before:  # aiortc opens a new encoder
                        session.encoder_restarts += 1
                return
        elif isinstance(packet, RtcpRtpfbPacket) and packet.fmt == RTCP_RTPFB_NACK:
            now_abs = _abs_send_time_now()
            if not all(can_resend(sender, seq, now_abs) for seq in packet.lost):
                if clock() - last_keyframe >= KEYFRAME_MIN_INTERVAL_S:
                    last_keyframe = clock()
                    session.loss_keyframes += 1
                    sender._send_keyframe()
                return
        await handle(packet)

    sender._handle_rtcp_packet = _handle
    encode_next = sender._next_encoded_frame  # called on the loop for each frame the sender sends

    async def _next_encoded_frame(codec):
        if quiet.send():
            return await encode_next(codec)
        await session.track.recv()  # taken at the viewer's pace, so the frame after the silence is fresh
        return None  # aiortc's sender sends nothing for it

    sender._next_encoded_frame = _next_encoded_frame
