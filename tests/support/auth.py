"""Users for tests that turn sign-in on: made in the database before the app opens it."""

from __future__ import annotations

from pathlib import Path

from rover_web.auth.accounts import Accounts
from rover_web.storage.db import Database

PASSWORD = "correct horse battery"
ROLES = ("viewer", "operator", "admin")


def add_users(db_path: str | Path, *roles: str) -> dict[str, str]:
    """One user per role, named after it; returns {role: API token}."""
    db = Database(db_path)
    accounts = None
    try:
        accounts = Accounts(db)
        tokens = {}
        for role in roles or ROLES:
            accounts.add_user(role, role, PASSWORD)
            tokens[role] = accounts.create_token(role, "tests")[1]
        return tokens
    finally:
        if accounts is not None:
            accounts.gate.close()  # its hashing threads
        db.close()


def sign_in(client, name: str, password: str = PASSWORD):
    """Sign a Flask test client (or a requests.Session against a URL) in through the form."""
    return client.post("/login", data={"username": name, "password": password})


def bearer(server, role: str) -> dict[str, str]:
    """The Authorization header of `server.tokens[role]` (the signed_server fixtures)."""
    return {"Authorization": f"Bearer {server.tokens[role]}"}
