"""Who is making the current request: a signed-in user (session cookie or API token), or nobody."""

from __future__ import annotations

from flask_login import AnonymousUserMixin, UserMixin, current_user

from rover_web.core.state import current_feature

from .policy import role_allows
from .revocation import NOTHING_TO_REVOKE, CloseFn, Credential, Registration
from .service import AuthService


class SignedIn(UserMixin):
    def __init__(self, credential: Credential, session_id: str | None = None):
        self.credential = credential  # what open streams are registered with (revocation.py)
        self.name = credential.user
        self.role = credential.role
        self.via = credential.via  # "session" or "token"
        self._session_id = session_id

    def get_id(self) -> str | None:
        # What Flask-Login keeps in the cookie: the session's random id, never the user's name, so
        # a cookie means nothing once its session ends (sessions.py).
        return self._session_id


class Anonymous(AnonymousUserMixin):
    name = None
    role = None
    via = None
    credential = None


def current_identity() -> SignedIn | Anonymous:
    return current_user._get_current_object()


def current_credential() -> Credential | None:
    """The credential the current request was let in with; None when not signed in."""
    return current_user.credential if current_user.is_authenticated else None


def signed_in_name() -> str | None:
    """The signed-in user's name, or None (sign-in off, or not signed in)."""
    return getattr(current_user, "name", None) if current_user.is_authenticated else None


def may(role: str, sign_in_on: bool) -> bool:
    """Whether the current request may act with `role` (always, when sign-in is off)."""
    if not sign_in_on:
        return True
    return current_user.is_authenticated and role_allows(current_user.role, role)


def on_revoke(close: CloseFn) -> Registration:
    """Register the current request's credential with `close`; a no-op outside sign-in."""
    auth = current_feature(AuthService)
    credential = current_credential() if auth.sign_in_on() else None
    if credential is None:
        return NOTHING_TO_REVOKE
    return auth.revocations.register(credential, close)
