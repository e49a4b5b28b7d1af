"""RosRuntime's shared raw subscriptions (the high-rate topics several features read, /odom) against
a real publisher in another process: one subscription on the app's node that the executor never
waits on, taken by a thread of its own, every callback served, and a clean stop."""

import threading
import time

import pytest

from rover_web.ros.runtime import RosRuntime
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

ODOM = "nav_msgs/msg/Odometry"


def odom(x: float) -> dict:
    return {"header": {"frame_id": "odom"}, "pose": {"pose": {"position": {"x": x}, "orientation": {"w": 1.0}}}}


def readers():
    """What two readers of one shared subscription received, the threads they ran on, and reader(name)."""
    got: dict[str, list] = {"a": [], "b": []}
    threads: set[str] = set()

    def reader(name):
        def on_raw(raw: bytes) -> None:
            threads.add(threading.current_thread().name)
            got[name].append(raw)
        return on_raw

    return got, threads, reader


def test_a_shared_raw_subscription_is_taken_off_the_executor_and_serves_every_reader(ros_peer):
    runtime = RosRuntime("shared_taker_test")
    runtime.start()
    got, threads, reader = readers()

    try:
        assert runtime.subscribe(ODOM, "/shared_odom", reader("a"), qos=10, raw=True, share=True) is None
        runtime.subscribe(ODOM, "/shared_odom", reader("b"), qos=10, raw=True, share=True)
        assert "/shared_odom" not in [s.topic_name for s in runtime.node.subscriptions]  # no executor sees it
        peer = ros_peer("shared_odom_publisher")
        peer.advertise("/shared_odom", ODOM, qos=10)
        peer.wait_match("/shared_odom")
        assert peer.graph(["/shared_odom"])["subscribers"]["/shared_odom"] == 1  # one, for both readers
        x = 0.0

        def some_arrived():
            nonlocal x
            x += 1.0
            peer.publish("/shared_odom", odom(x))
            return got["a"] and got["b"]

        wait_until(some_arrived, 10, "the shared subscription's messages")
        time.sleep(0.2)
        assert got["a"] == got["b"] and all(isinstance(raw, bytes) for raw in got["a"])
        assert threads == {"ros-shared-taker"}
        assert runtime.tracks("/shared_odom")  # still counted for /api/status
    finally:
        runtime.stop()
    assert not [t for t in threading.enumerate() if t.name == "ros-shared-taker"]
    before = len(got["a"])
    peer.publish("/shared_odom", odom(99.0))
    time.sleep(0.3)
    assert len(got["a"]) == before  # nothing after the stop


def test_a_shared_raw_subscription_can_stay_on_the_executor(ros_peer):
    """taker=False (the markers: heavy callbacks now and then): one subscription, on the executor, for both."""
    runtime = RosRuntime("shared_executor_test")
    runtime.start()
    got, threads, reader = readers()

    try:
        runtime.subscribe(ODOM, "/shared_slow", reader("a"), qos=10, raw=True, share=True, taker=False)
        runtime.subscribe(ODOM, "/shared_slow", reader("b"), qos=10, raw=True, share=True, taker=False)
        assert [s.topic_name for s in runtime.node.subscriptions].count("/shared_slow") == 1
        peer = ros_peer("shared_slow_publisher")
        peer.advertise("/shared_slow", ODOM, qos=10)
        peer.wait_match("/shared_slow")
        assert peer.graph(["/shared_slow"])["subscribers"]["/shared_slow"] == 1  # one DDS reader for both
        x = 0.0

        def some_arrived():
            nonlocal x
            x += 1.0
            peer.publish("/shared_slow", odom(x))
            return got["a"] and got["b"]

        wait_until(some_arrived, 10, "the shared subscription's messages")
        time.sleep(0.2)
        assert got["a"] == got["b"] and all(isinstance(raw, bytes) for raw in got["a"])
        assert "ros-shared-taker" not in threads
    finally:
        runtime.stop()
