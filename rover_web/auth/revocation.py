"""Open streams and sockets end when the credentials they were opened with do.

A request's credentials are checked once, before its view; a teleop socket or an event stream
then lives for hours. So every long-lived response registers here with the credential it was
opened with (`Credential`: the user, their session epoch, and the session or token) and a close
callback. When a credential may have ended (a token revoked, a user removed, a role or password
changed, a sign-out, "sign out everywhere") the change is written to the database first, then
`check()` asks the database about every registered credential and calls the callbacks of those
that ended, with a short reason. The database is the only truth, so a change made by
`flask users ...` in another process counts too: a background loop runs `check()` every
CHECK_PERIOD_S while anything is registered.

How a feature uses it (docs/security.md#what-revocation-reaches; `on_revoke` lives in identity.py,
beside the credential it reads, so this module depends on nothing else of auth/):

    from rover_web.auth import on_revoke
    with on_revoke(close):       # close(reason: str), called at most once, from another thread
        serve_until_closed()

`on_revoke` registers the current request's credential (a no-op when sign-in is off for the
request). Code outside a request (another helper's WebRTC sessions, say) keeps the credential
with `current_credential()` while it has the request, then calls
`Revocations.register(credential, close)` on `current_feature(AuthService).revocations`.
Every response whose body is streamed is registered already (auth/routes.py): revocation shuts
its socket down. A close callback must not block: stop what moves, ask for the close, return.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass

log = logging.getLogger(__name__)

CHECK_PERIOD_S = 1.0  # the backstop for changes made by other processes (the CLI)

CloseFn = Callable[[str], object]


@dataclass(frozen=True)
class Credential:
    """What a request was let in with. `key` is the session's digest or the token's id."""

    user: str
    role: str
    epoch: str
    via: str  # "session" or "token"
    key: str


class Registration:
    """One registered stream; `cancel()` (or leaving the `with`) when it ends by itself."""

    __slots__ = ("credential", "_close", "_owner", "__weakref__")

    def __init__(self, owner: Revocations | None, credential: Credential | None, close: CloseFn):
        self._owner = owner
        self.credential = credential
        self._close = close

    def cancel(self) -> None:
        if self._owner is not None:
            self._owner._remove(self)

    def __enter__(self) -> Registration:
        return self

    def __exit__(self, *exc) -> None:
        self.cancel()


NOTHING_TO_REVOKE = Registration(None, None, lambda _reason: None)


class Revocations:
    def __init__(self, ended: Callable[[Credential], str | None]):
        """`ended(credential)`: why it no longer holds (e.g. "token revoked"), or None while it does."""
        self._ended = ended
        self._lock = threading.Lock()
        self._check_lock = threading.Lock()
        self._open: set[Registration] = set()
        self.any_open = threading.Event()  # the backstop loop sleeps while nothing is registered

    def register(self, credential: Credential, close: CloseFn) -> Registration:
        """Call `close(reason)` once `credential` ends; until `cancel()`."""
        registration = Registration(self, credential, close)
        with self._lock:
            self._open.add(registration)
            self.any_open.set()
        return registration

    def _remove(self, registration: Registration) -> bool:
        with self._lock:
            if registration not in self._open:
                return False
            self._open.discard(registration)
            if not self._open:
                self.any_open.clear()
            return True

    @property
    def count(self) -> int:
        return len(self._open)

    def check(self) -> int:
        """Close every registration whose credential has ended; returns how many were closed."""
        with self._check_lock:  # one check at a time: a credential is asked about once per check
            with self._lock:
                registrations = list(self._open)
            verdicts: dict[Credential, str | None] = {}
            closed = 0
            for registration in registrations:
                credential = registration.credential
                if credential not in verdicts:
                    verdicts[credential] = self._ended(credential)
                reason = verdicts[credential]
                if reason is not None and self._remove(registration):
                    closed += 1
                    try:
                        registration._close(reason)
                    except Exception:  # one broken callback must not keep the others open
                        log.exception("closing a stream of %s after '%s' failed", credential.user, reason)
            if closed:
                log.info("revocation: closed %d stream(s) (%s)", closed,
                         "; ".join(sorted({f"{c.user}: {r}" for c, r in verdicts.items() if r})))
            return closed
