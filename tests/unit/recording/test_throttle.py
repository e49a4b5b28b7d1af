"""The camera throttle keeps a camera at the cap's rate through arrival jitter, and caps a faster one."""

import random

from rover_web.recording import service


class Sink:
    def __init__(self):
        self.kept = 0

    def offer(self, topic, data):
        self.kept += 1


def run(monkeypatch, arrivals, hz):
    clock = iter(arrivals)
    now = [0.0]

    def monotonic():
        return now[0]

    monkeypatch.setattr(service.time, "monotonic", monotonic)
    sink = Sink()
    callback = service._throttled(sink, "/camera", 1.0 / hz)
    for t in clock:
        now[0] = t
        callback(b"frame")
    return sink.kept


def test_a_jittery_camera_at_the_cap_keeps_every_frame(monkeypatch):
    rng = random.Random(3)
    arrivals = [1.0 + i * 0.1 + rng.uniform(-0.01, 0.01) for i in range(200)]
    assert run(monkeypatch, arrivals, hz=10) == 200


def test_a_faster_camera_is_cut_to_the_cap_on_average(monkeypatch):
    arrivals = [1.0 + i / 30 for i in range(300)]  # 30 fps for 10 s, capped at 2 Hz
    assert 19 <= run(monkeypatch, arrivals, hz=2) <= 22
