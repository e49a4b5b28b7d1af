"""The camera throttle keeps a camera at the cap's rate through arrival jitter, and caps a faster one;
it goes by each frame's reception time, so frames taken together after a wait are not dropped."""

import random

from rover_web.recording import service


class Sink:
    def __init__(self):
        self.kept = 0

    def offer(self, topic, data, log_time_ns=None):
        self.kept += 1


def run(arrivals, hz):
    sink = Sink()
    callback = service._throttled(sink, "/camera", 1.0 / hz)
    for t in arrivals:
        callback(b"frame", int(t * 1e9))
    return sink.kept


def test_a_jittery_camera_at_the_cap_keeps_every_frame():
    rng = random.Random(3)
    arrivals = [1.0 + i * 0.1 + rng.uniform(-0.01, 0.01) for i in range(200)]
    assert run(arrivals, hz=10) == 200


def test_a_faster_camera_is_cut_to_the_cap_on_average():
    arrivals = [1.0 + i / 30 for i in range(300)]  # 30 fps for 10 s, capped at 2 Hz
    assert 19 <= run(arrivals, hz=2) <= 22


def test_frames_taken_together_after_a_wait_are_kept_by_their_reception_times():
    sink = Sink()
    callback = service._throttled(sink, "/camera", 0.1)
    for i in range(10):  # a second of 10 fps frames, all taken at once a second late
        callback(b"frame", int((1.0 + i * 0.1) * 1e9))
    assert sink.kept == 10
