"""Who is making the current request: a signed-in user (session cookie or API token), or nobody."""

from __future__ import annotations

from flask_login import AnonymousUserMixin, UserMixin, current_user

from .policy import role_allows


class SignedIn(UserMixin):
    def __init__(self, name: str, role: str, via: str):
        self.name = name
        self.role = role
        self.via = via  # "session" or "token"

    def get_id(self) -> str:
        return self.name


class Anonymous(AnonymousUserMixin):
    name = None
    role = None
    via = None


def current_identity() -> SignedIn | Anonymous:
    return current_user._get_current_object()


def signed_in_name() -> str | None:
    """The signed-in user's name, or None (sign-in off, or not signed in)."""
    return getattr(current_user, "name", None) if current_user.is_authenticated else None


def may(role: str, sign_in_on: bool) -> bool:
    """Whether the current request may act with `role` (always, when sign-in is off)."""
    if not sign_in_on:
        return True
    return current_user.is_authenticated and role_allows(current_user.role, role)
