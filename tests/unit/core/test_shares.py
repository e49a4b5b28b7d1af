"""Per-client shares and the driving reserve of the stream cap, and per-client shares of leases
(issue 27). The live-server tests (tests/integration/web/test_stream_shares.py) cover the routes;
these cover what a loopback test cannot make: several client addresses."""

import pytest

from rover_web.core.leases import Full, Leases, ShareUsed
from rover_web.core.streams import StreamLimit, TooManyStreams


def test_each_client_holds_at_most_its_share_and_gets_it_back():
    limit = StreamLimit(10)
    mine = [limit.acquire("sse", "addr:10.0.0.5", per_client=2) for _ in range(2)]
    with pytest.raises(TooManyStreams, match="MAX_STREAMS_PER_CLIENT"):
        limit.acquire("sse", "addr:10.0.0.5", per_client=2)
    limit.acquire("sse", "addr:10.0.0.6", per_client=2)  # another address is not held back
    mine[0].release()
    mine[0].release()  # twice changes nothing
    assert limit.held_by("addr:10.0.0.5") == 1
    limit.acquire("sse", "addr:10.0.0.5", per_client=2)
    assert limit.snapshot()["open"] == 3


def test_the_reserve_is_kept_for_callers_that_may_use_it():
    limit = StreamLimit(4)
    common = [limit.acquire("sse", f"addr:10.0.0.{i}", reserved=2, may_reserve=False) for i in range(2)]
    with pytest.raises(TooManyStreams, match="STREAMS_RESERVED"):
        limit.acquire("mjpeg", "addr:10.0.0.9", reserved=2, may_reserve=False)
    limit.acquire("teleop", "addr:10.0.0.9", reserved=2)
    limit.acquire("teleop", "addr:10.0.0.9", reserved=2)
    with pytest.raises(TooManyStreams):
        limit.acquire("teleop", "addr:10.0.0.9", reserved=2)  # the cap itself
    common[0].release()  # a slot of the common part: free for anyone again
    limit.acquire("sse", None, reserved=2, may_reserve=False)
    with pytest.raises(TooManyStreams):
        limit.acquire("sse", None, reserved=2, may_reserve=False)


def test_driving_ending_does_not_lend_the_reserve_to_others():
    limit = StreamLimit(3)
    drive = limit.acquire("teleop", None, reserved=2)
    limit.acquire("sse", None, reserved=2, may_reserve=False)
    with pytest.raises(TooManyStreams):
        limit.acquire("sse", None, reserved=2, may_reserve=False)
    drive.release()
    with pytest.raises(TooManyStreams):
        limit.acquire("sse", None, reserved=2, may_reserve=False)


def test_a_reserve_as_large_as_the_cap_still_leaves_one_slot():
    limit = StreamLimit(2)
    limit.acquire("sse", None, reserved=5, may_reserve=False)
    with pytest.raises(TooManyStreams):
        limit.acquire("sse", None, reserved=5, may_reserve=False)


def test_a_client_holds_only_its_share_of_different_leases():
    opened, closed = [], []
    leases = Leases(lambda key: opened.append(key) or key, closed.append, linger_s=0, max_keys=8)
    leases.acquire("a", client="u1", share=2)
    leases.acquire("b", client="u1", share=2)
    with pytest.raises(ShareUsed):
        leases.acquire("c", client="u1", share=2)
    assert issubclass(ShareUsed, Full)
    leases.acquire("a", client="u1", share=2)  # one it holds costs nothing more
    leases.acquire("c", client="u2", share=2)  # and others are not held back
    leases.acquire("a", client="u2", share=2)  # nor by sharing one u1 holds
    leases.release("b", client="u1")
    leases.acquire("c", client="u1", share=2)
    assert opened == ["a", "b", "c"]
    leases.reap()
    assert closed == ["b"]
