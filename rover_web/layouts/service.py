"""One robot's layouts: its store, and which layout the current request's user sees."""

from __future__ import annotations

from rover_web.auth import AuthService, signed_in_name
from rover_web.core.state import current_feature

from .store import SHARED, LayoutStore


class LayoutService:
    def __init__(self, store: LayoutStore):
        self.store = store

    @staticmethod
    def user_key() -> str:
        """Whose choice a request reads and writes: the signed-in user's; with sign-in off (or for a
        request that needs none), the one choice every browser shares."""
        if not current_feature(AuthService).sign_in_on():
            return SHARED
        return signed_in_name() or SHARED

    def active(self) -> tuple[int | None, dict]:
        return self.store.active(self.user_key())
