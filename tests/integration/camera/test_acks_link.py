"""Why pages acknowledge: through the link emulator's `wifi-edge` profile (2 Mbit/s, 60 ± 40 ms each
way, a 256 kB buffer), which terminates TCP as nginx or a satellite link's proxy does, so the
server's socket looks empty while video waits in the link. An adaptive stream whose client
acknowledges what it receives (the acks cross the link too) keeps the link's queue to about a frame;
the same stream without acks, through the same emulator, fills the buffer (docs/field.md).

Byte and queue assertions with wide margins, never times: the machine is shared."""

import threading

import pytest

from rover_web.linkemu import LinkEmulator
from tests.integration.camera.test_stream import wait_listed
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

SMALL_QUEUE = 64_000  # about a 21 kB frame plus the queue budget, with room to spare
FULL_QUEUE = 150_000  # most of the 256 kB buffer


class QueueWatch:
    """The largest downlink queue of the emulator, sampled until stopped."""

    def __init__(self, link):
        self.link, self.most, self.samples = link, 0, 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        while not self._stop.wait(0.02):
            self.most = max(self.most, self.link.counters()["down"]["queue_bytes"])
            self.samples += 1

    def stop(self) -> int:
        self._stop.set()
        self._thread.join(5)
        return self.most


def down_queue(link) -> int:
    return link.counters()["down"]["queue_bytes"]


def test_an_acking_client_keeps_the_link_queue_small_where_an_unacked_stream_fills_it(
        live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/through_link"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)  # ~21 kB frames, 630 kB/s asked of a 250 kB/s link
    wait_listed(live_server, topic)
    with LinkEmulator("wifi-edge", listen="127.0.0.1:0", target=f"127.0.0.1:{live_server.port}", seed=5) as link:
        url = f"http://127.0.0.1:{link.port}"
        acked = mjpeg_client(f"{url}/stream?topic={topic}&viewer=acked&ack=1", ack=True)
        acked.wait_frames(3, timeout=60)
        watch = QueueWatch(link)
        acked.wait_frames(acked.count + 40, timeout=120)
        most = watch.stop()
        assert acked.acker.acked > 0 and set(acked.acker.answers) == {204}
        assert watch.samples > 10
        assert most < SMALL_QUEUE, f"the link held {most} bytes behind an acknowledging client"
        acked.close()
        wait_until(lambda: down_queue(link) == 0, 30, "the link drained")

        # The same adaptive stream, not acknowledged: the emulator takes the bytes at once, the
        # server's socket looks empty, and the video fills the link's buffer.
        plain = mjpeg_client(f"{url}/stream?topic={topic}&viewer=plain")
        plain.wait_frames(1, timeout=60)
        wait_until(lambda: down_queue(link) > FULL_QUEUE, 60, "video filling the link's buffer")
