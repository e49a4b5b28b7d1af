"""Teleop sessions: one per socket, each with its epoch, arming and link. Pure Python.

One operator at a time: the first session to drive holds control; others are view-only until the
holder releases, disconnects or another session explicitly takes over. Who holds control, and the
rules that stop the robot at a handover, are the controller's (control.py); this module keeps the
book of open sessions, always under the controller's lock.
"""

from __future__ import annotations

import itertools
import secrets
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from .link import LinkMeter


@dataclass(eq=False)
class Session:
    """One teleop socket. `outbox` holds messages for it; only its own socket thread sends them,
    woken by `wake()` (set by that thread) as soon as one is queued."""

    id: str
    name: str
    epoch: int = 0
    # False from an e-stop release until this socket sends a neutral input: a stick or key held
    # through the release must not move the robot the moment the latch opens.
    armed: bool = True
    source: str | None = None  # of its last accepted drive frame, so only a change is logged
    outbox: deque = field(default_factory=lambda: deque(maxlen=64))
    wake: Callable[[], None] | None = None
    link: LinkMeter = field(default_factory=LinkMeter)
    # The language of the request that opened it (api_messages.request_catalogues): its error frames
    # are made on the reader's thread, outside any request. None: English.
    catalogues: tuple | None = None

    def public(self) -> dict:
        return {"id": self.id, "name": self.name}


class Sessions:
    """The open sessions of one controller, numbered in the order they came."""

    def __init__(self, clock: Callable[[], float]):
        self._clock = clock
        self._open: dict[str, Session] = {}
        self._numbers = itertools.count(1)

    def open(self, name: str | None) -> Session:
        number = next(self._numbers)
        session = Session(id=f"{number}-{secrets.token_hex(3)}", name=name or f"operator {number}",
                          link=LinkMeter(self._clock))
        self._open[session.id] = session
        return session

    def close(self, session: Session) -> bool:
        """False if it was not open."""
        return self._open.pop(session.id, None) is not None

    def is_open(self, session: Session) -> bool:
        return session.id in self._open

    def __iter__(self) -> Iterator[Session]:
        return iter(list(self._open.values()))

    def __len__(self) -> int:
        return len(self._open)
