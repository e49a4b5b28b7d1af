from rover_web.ros.topic_stats import TopicStats


def test_rate_and_age_from_arrivals():
    s = TopicStats("/odom", "nav_msgs/msg/Odometry")
    for i in range(51):
        s.record(now=100.0 + i * 0.02)  # 50 Hz for one second
    snap = s.snapshot(stale_after_s=2.0, now=101.01)
    assert abs(snap["rate_hz"] - 50.0) < 0.1
    assert snap["age_s"] == 0.01 and snap["fresh"] and snap["count"] == 51


def test_silent_topic_goes_stale_and_its_rate_decays():
    s = TopicStats("/odom", "x")
    for i in range(11):
        s.record(now=i * 0.1)
    snap = s.snapshot(stale_after_s=2.0, now=4.0)
    assert not snap["fresh"] and snap["age_s"] == 3.0
    assert snap["rate_hz"] < 10.0 / 3
    assert s.snapshot(2.0, now=100.0)["rate_hz"] == 0.0


def test_never_heard():
    snap = TopicStats("/fix", "x").snapshot(2.0, now=5.0)
    assert snap["age_s"] is None and not snap["fresh"] and snap["rate_hz"] == 0.0
