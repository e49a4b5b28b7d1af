"""One asyncio event loop on its own thread: where every peer connection of the app lives.

aiortc is asyncio code; Flask's request threads and the ROS executor are not. The camera package
starts one `LoopThread` with the app and stops it at shutdown; request threads hand it work with
`run(coro, timeout_s)` (asyncio.run_coroutine_threadsafe, waited with a timeout), and nothing on
it ever waits on the ROS executor. Blocking work (decoding camera frames, aiortc's encoder, the
teleop controller) goes to thread pools, so one slow frame never stalls another viewer's packets.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import threading
from collections.abc import Awaitable, Callable
from typing import Any, TypeVar

log = logging.getLogger(__name__)

T = TypeVar("T")


class LoopStopped(RuntimeError):
    """The loop is not running (not started yet, or the app is shutting down)."""


class LoopThread:
    def __init__(self, name: str = "webrtc-loop"):
        self.name = name
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._stopped = False
        self._lock = threading.Lock()

    def start(self) -> None:
        with self._lock:
            if self._thread is not None:
                return
            self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
            self._thread.start()
        self._ready.wait(10.0)

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        self._loop = loop
        self._ready.set()
        try:
            loop.run_forever()
        finally:
            try:
                loop.run_until_complete(loop.shutdown_asyncgens())
                loop.run_until_complete(loop.shutdown_default_executor())
            except Exception:  # pragma: no cover - closing anyway
                log.exception("closing the WebRTC loop")
            loop.close()

    @property
    def loop(self) -> asyncio.AbstractEventLoop:
        if self._loop is None or self._stopped or not self._loop.is_running():
            raise LoopStopped("the WebRTC loop is not running")
        return self._loop

    @property
    def running(self) -> bool:
        return self._loop is not None and not self._stopped and self._loop.is_running()

    def in_loop(self) -> bool:
        return self._thread is threading.current_thread()

    def submit(self, coro: Awaitable[T]) -> concurrent.futures.Future[T]:
        try:
            return asyncio.run_coroutine_threadsafe(coro, self.loop)  # type: ignore[arg-type]
        except LoopStopped:
            coro.close()  # type: ignore[attr-defined]  # never awaited: no "was never awaited" warning
            raise

    def run(self, coro: Awaitable[T], timeout_s: float) -> T:
        """Run `coro` on the loop and wait for its result; on timeout it is cancelled and TimeoutError raised."""
        if self.in_loop():
            raise RuntimeError("LoopThread.run called from the loop itself; await the coroutine instead")
        future = self.submit(coro)
        try:
            return future.result(timeout_s)
        except concurrent.futures.TimeoutError:
            future.cancel()
            raise TimeoutError(f"the WebRTC loop did not answer within {timeout_s:g} s") from None

    def call_soon(self, fn: Callable[..., Any], *args: Any) -> None:
        """From any thread; ignored once the loop has stopped (nothing is left to tell)."""
        loop = self._loop
        if loop is None or self._stopped or loop.is_closed():
            return
        try:
            loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:  # closed between the check and the call
            pass

    def stop(self, timeout_s: float = 5.0) -> None:
        """Stop the loop and join its thread; pending tasks are cancelled first."""
        with self._lock:
            if self._stopped or self._loop is None:
                self._stopped = True
                return
            loop, thread = self._loop, self._thread
        if loop.is_running():
            try:
                asyncio.run_coroutine_threadsafe(_cancel_all(), loop).result(timeout_s)
            except Exception:
                log.warning("WebRTC loop tasks did not end within %.1f s", timeout_s)
        self._stopped = True
        loop.call_soon_threadsafe(loop.stop)
        if thread is not None:
            thread.join(timeout_s)
            if thread.is_alive():
                log.warning("the WebRTC loop thread did not end within %.1f s", timeout_s)


async def _cancel_all() -> None:
    current = asyncio.current_task()
    tasks = [t for t in asyncio.all_tasks() if t is not current]
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
