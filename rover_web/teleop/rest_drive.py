"""A REST drive ends with the credential that started it (issue 27).

`POST /api/teleop` answers at once and the robot then drives for up to
ROVER_WEB_TELEOP_REST_MAX_DURATION_S with no socket left open, so the socket's own revocation
(`on_revoke` around its serve loop, routes.py) has nothing to hang on. Here the request registers
its credential for the drive it starts: revoking the token, removing the user, changing their
role or password, or signing out stops that drive at once (one zero). A drive someone else
started since is theirs and goes on.

Only the drive under way can move the robot, so only its registration is kept: the next REST
command (anyone's) cancels the one before, and a revocation cancels its own. One registration may
thus outlive its drive until then; its callback finds another command, or none, and does nothing.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from .control import TeleopController

log = logging.getLogger(__name__)


class RestDrives:
    def __init__(self, controller: TeleopController):
        self.controller = controller
        self._lock = threading.Lock()  # one REST start at a time: the kept registration is the held drive's
        self._watched: tuple[object, object] | None = None  # the latest REST drive's (owner, registration)

    def start(self, command: str, speed: float, duration_s: float,
              watch: Callable[[Callable[[str], object]], object]) -> tuple[float, float]:
        """Start a REST drive; `watch(close)` registers the request's credential (auth's on_revoke)."""
        owner = object()
        with self._lock:
            # Registered before the drive starts: a revocation between the two finds no drive of its
            # own and does nothing, rather than miss one.
            registration = watch(lambda reason: self._revoked(owner, reason))
            try:
                result = self.controller.rest_command(command, speed, duration_s, owner)
            except BaseException:
                registration.cancel()
                raise
            previous, self._watched = self._watched, (owner, registration)
        if previous is not None:
            previous[1].cancel()
        return result

    def _revoked(self, owner: object, reason: str) -> None:
        # A revocation callback must not block: end_rest takes the controller's lock only to
        # publish one zero.
        if self.controller.end_rest(owner, "revoked"):
            log.info("REST drive stopped: %s", reason)
        with self._lock:
            if self._watched is not None and self._watched[0] is owner:
                self._watched = None

    def close(self) -> None:
        with self._lock:
            watched, self._watched = self._watched, None
        if watched is not None:
            watched[1].cancel()
