"""Frames are held while the browser sends no feedback (an outage), one let through now and then."""

from rover_web.camera.webrtc.silence import PROBE_S, SILENCE_S, Silence


class Clock:
    t = 50.0

    def __call__(self):
        return self.t


def frames(silence, clock, seconds, fps=20):
    """How many of the frames in `seconds` at `fps` would be sent."""
    sent = 0
    for _ in range(round(seconds * fps)):
        sent += silence.send()
        clock.t += 1 / fps
    return sent


def test_every_frame_goes_before_the_first_feedback():
    # A browser reports only once media arrives: holding frames until then would never start.
    clock = Clock()
    silence = Silence(clock)
    assert frames(silence, clock, 3 * SILENCE_S) == 3 * SILENCE_S * 20 and silence.held == 0


def test_every_frame_goes_while_reports_keep_coming_as_far_apart_as_a_browser_leaves_them():
    clock = Clock()
    silence = Silence(clock)
    for _ in range(20):
        silence.heard()
        assert frames(silence, clock, 1.5) == 30  # aiortc's receiver reports 0.5 to 1.5 s apart
    assert silence.held == 0


def test_a_silence_holds_frames_but_one_per_probe_interval_until_feedback_comes_back():
    clock = Clock()
    silence = Silence(clock)
    silence.heard()
    clock.t += SILENCE_S - 0.01
    assert silence.send()
    clock.t += 0.02  # quiet for longer than SILENCE_S now
    period = 0.047  # 21.3 fps: no frame falls on a probe interval's edge
    sent = []
    for _ in range(75):  # 3.5 s
        sent.append(silence.send())
        clock.t += period
    # The first at once, then each the first frame PROBE_S after the last one sent (22 × 47 ms).
    assert PROBE_S == 1.0 and [i for i, s in enumerate(sent) if s] == [0, 22, 44, 66]
    assert silence.held == 75 - 4
    silence.heard()
    assert frames(silence, clock, 1.0) == 20
