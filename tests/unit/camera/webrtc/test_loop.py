"""LoopThread: work handed over from other threads, timeouts that cancel, a stop that joins."""

import asyncio
import threading

import pytest

from rover_web.camera.webrtc.loop import LoopStopped, LoopThread


@pytest.fixture
def loop():
    made = LoopThread("test-loop")
    made.start()
    yield made
    made.stop()


def test_runs_coroutines_on_its_own_thread(loop):
    async def where():
        return threading.current_thread().name
    assert loop.run(where(), 5) == "test-loop"


def test_a_timeout_cancels_the_work(loop):
    cancelled = threading.Event()

    async def forever():
        try:
            await asyncio.sleep(60)
        except asyncio.CancelledError:
            cancelled.set()
            raise
    with pytest.raises(TimeoutError):
        loop.run(forever(), 0.1)
    assert cancelled.wait(5)


def test_stop_cancels_pending_tasks_and_joins():
    loop = LoopThread("test-loop-2")
    loop.start()
    cancelled = threading.Event()

    async def forever():
        try:
            await asyncio.sleep(60)
        except asyncio.CancelledError:
            cancelled.set()
            raise
    loop.submit(forever())
    loop.stop()
    assert cancelled.is_set()
    assert not [t for t in threading.enumerate() if t.name == "test-loop-2"]
    with pytest.raises(LoopStopped):
        loop.run(forever(), 1)  # refused, and the coroutine closed (no "never awaited" warning)
    loop.call_soon(print)  # ignored once stopped
