"""A Bottleneck driven by an asyncio loop: one task delivers what has arrived and wakes the readers
waiting for room in the buffer."""

from __future__ import annotations

import asyncio
import logging
import time

from .bottleneck import Bottleneck, Flow

log = logging.getLogger(__name__)


class Direction:
    def __init__(self, name: str, bottleneck: Bottleneck):
        self.name = name
        self.bottleneck = bottleneck
        self._wake = asyncio.Event()
        self._room = asyncio.Event()
        self._room.set()

    def push(self, flow: Flow, data: bytes) -> bool:
        ok = self.bottleneck.push(flow, data)
        if self.bottleneck.room() <= 0:
            self._room.clear()
        self._wake.set()
        return ok

    def room(self) -> int:
        return self.bottleneck.room()

    async def wait_room(self, need: int = 1) -> int:
        """Until the buffer has room for `need` bytes: a TCP relay reads nothing meanwhile, so the
        sender is pushed back."""
        while (room := self.bottleneck.room()) < need:
            self._room.clear()
            await self._room.wait()
        return room

    def kick(self) -> None:
        """Look again now (the profile or the schedule changed)."""
        self._wake.set()

    async def run(self) -> None:
        while True:
            for flow, data in self.bottleneck.due():
                try:
                    flow.deliver(data)
                except Exception:  # a peer gone mid-write: its connection is closed by its relay
                    log.debug("delivery to %s failed", flow.name, exc_info=True)
            if self.bottleneck.room() > 0:
                self._room.set()
            wake_at = self.bottleneck.next_wakeup()
            self._wake.clear()
            timeout = None if wake_at is None else max(0.0, wake_at - time.monotonic())
            try:
                await asyncio.wait_for(self._wake.wait(), timeout)
            except TimeoutError:
                pass
