"""A jitter buffer for the bench's aiortc viewers that gives frames to the decoder as a browser does.

aiortc's own (aiortc/jitterbuffer.py, 1.16) made the link bench measure aiortc, not our video:
- it hands a frame over only when the first packet of the *next* frame arrives, so every frame
  waited one frame interval more (33 to 100 ms here) than in a browser, which goes by the RTP
  marker bit that ends a frame;
- a packet lost for good (the radio's 3 s outage: the sender keeps only 128 packets to
  retransmit) stops it at that hole until 512 packets have come after it, about 10 s of video on
  the radio, and only then asks for a keyframe. What it had held back then came out as a burst of
  frames 10 s old, the first of them decoded against missing references (no readable time code).
  A browser (libwebrtc) gives such a frame up after some NACK rounds, drops the frames that depend
  on it, asks for a keyframe and asks again until one comes.

This one does the same: a frame is complete at its marker bit when none of its packets is
missing; a hole still open after GIVE_UP_S (several NACK round trips on the bench's links), or
followed by a whole keyframe, is given up, the frames after it are dropped until a VP8 keyframe,
and a keyframe is asked for (the PLI aiortc's receiver sends when `add` says so) then and every
KEYFRAME_RETRY_S until one comes.
Installed by `install(receiver)` on a video RTCRtpReceiver, a private attribute (aiortc is pinned).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from aiortc.jitterbuffer import JitterFrame
from aiortc.utils import uint16_add, uint16_gt

CAPACITY = 512  # packets, as aiortc's
GIVE_UP_S = 1.0
KEYFRAME_RETRY_S = 0.5


def starts_vp8_frame(packet) -> bool:
    """The VP8 payload descriptor (RFC 7741) says S (start of a partition) and partition 0."""
    return bool(packet.payload) and packet.payload[0] & 0x17 == 0x10


def is_vp8_keyframe(packet) -> bool:
    """A frame's first packet, depayloaded, starts with the VP8 frame tag: bit 0 clear on a keyframe."""
    return bool(packet._data) and not packet._data[0] & 0x01


class BrowserJitterBuffer:
    def __init__(self, spill: Callable[[object, JitterFrame], None], clock: Callable[[], float] = time.monotonic):
        """`spill(packet, frame)`: to the decoder now, for each frame completed before the one `add`
        returns (aiortc's receiver takes one frame per packet; a retransmission can complete several)."""
        self._spill = spill
        self._clock = clock
        self._packets: dict[int, object] = {}  # sequence number → RtpPacket (depayloaded in ._data)
        self._arrived: dict[int, float] = {}  # sequence number → when it came
        self._next: int | None = None  # the first sequence number neither handed over nor given up
        self._need_key = False
        self._asked = -float("inf")
        self.given_up = 0  # holes given up
        self.dropped = 0  # complete frames dropped while waiting for a keyframe

    def add(self, packet) -> tuple[bool, JitterFrame | None]:
        seq = packet.sequence_number
        if self._next is None:
            self._next = seq
        elif uint16_gt(self._next, seq):
            return False, None  # handed over or given up already: a late retransmission
        now = self._clock()
        self._packets[seq], self._arrived[seq] = packet, now
        if uint16_add(seq, -self._next) >= CAPACITY:
            self._give_up()
        frames = self._take(now)
        for frame in frames[:-1]:
            self._spill(packet, frame)
        pli = False
        if self._need_key and now - self._asked >= KEYFRAME_RETRY_S:
            self._asked, pli = now, True
        return pli, frames[-1] if frames else None

    def _take(self, now: float) -> list[JitterFrame]:
        frames = []
        while (frame := self._frame_at_next()) is not None:
            if frame is not False:
                frames.append(frame)
        if (seen := self._hole_seen()) is not None and (now - seen >= GIVE_UP_S or self._keyframe_after_hole()):
            self._give_up()
            frames += self._take(now)
        return frames

    def _keyframe_after_hole(self) -> bool:
        """A whole keyframe has come after the hole: a browser decodes it at once, whatever is missing
        before it (it needs nothing earlier)."""
        held = self._held()
        for i, seq in enumerate(held):
            if seq != uint16_add(self._next, i):
                break
        else:
            return False
        for seq in held[i:]:
            first = self._packets[seq]
            if starts_vp8_frame(first) and is_vp8_keyframe(first):
                n = seq
                while (p := self._packets.get(n)) is not None and p.timestamp == first.timestamp:
                    if p.marker:
                        return True
                    n = uint16_add(n, 1)
        return False

    def _held(self) -> list[int]:
        return sorted(self._packets, key=lambda s: uint16_add(s, -self._next))

    def _hole_seen(self) -> float | None:
        """When the first hole from _next on was noticed: the arrival of the first packet after it."""
        for i, seq in enumerate(self._held()):
            if seq != uint16_add(self._next, i):
                return self._arrived[seq]
        return None

    def _frame_at_next(self) -> JitterFrame | bool | None:
        """The frame starting at _next if all its packets are here (False: complete but dropped,
        waiting for a keyframe); None while it is not complete."""
        first = self._packets.get(self._next)
        if first is None:
            return None
        packets, seq = [], self._next
        while (packet := self._packets.get(seq)) is not None and packet.timestamp == first.timestamp:
            packets.append(packet)
            if packet.marker:
                break
            seq = uint16_add(seq, 1)
        else:
            return None
        for p in packets:
            del self._packets[p.sequence_number], self._arrived[p.sequence_number]
        self._next = uint16_add(seq, 1)
        if self._need_key:
            if not (starts_vp8_frame(first) and is_vp8_keyframe(first)):
                self.dropped += 1
                return False
            self._need_key = False
        return JitterFrame(data=b"".join(p._data for p in packets), timestamp=first.timestamp)

    def _give_up(self) -> None:
        """Skip the frame with the hole (nothing before the hole is a whole frame, or it would have
        been handed over) to the next packet held that starts a frame; what follows is of use only
        from a keyframe on."""
        self.given_up += 1
        self._need_key = True
        held = self._held()
        past_hole = False
        for i, seq in enumerate(held):
            past_hole = past_hole or seq != uint16_add(self._next, i)
            if past_hole and starts_vp8_frame(self._packets[seq]):
                self._next = seq
                return
            del self._packets[seq], self._arrived[seq]
        self._next = uint16_add(held[-1], 1) if held else None


def install(receiver) -> BrowserJitterBuffer:
    """On a video RTCRtpReceiver, before it receives."""
    codecs = receiver._RTCRtpReceiver__codecs
    mapper = receiver._RTCRtpReceiver__timestamp_mapper
    decoder = receiver._RTCRtpReceiver__decoder_queue

    def spill(packet, frame: JitterFrame) -> None:  # what the receiver does with the frame `add` returns
        frame.timestamp = mapper.map(frame.timestamp)
        decoder.put((codecs[packet.payload_type], frame))

    buffer = BrowserJitterBuffer(spill)
    receiver._RTCRtpReceiver__jitter_buffer = buffer
    return buffer
