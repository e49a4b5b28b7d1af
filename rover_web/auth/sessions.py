"""Sign-in sessions and each user's session epoch, in the app's SQLite database.

The session cookie holds only a random session id (256 bits, signed by Flask); the server keeps
its SHA-256, the user, the user's epoch at sign-in and when it expires. A request's session holds
while its row exists, has not expired and carries the user's current epoch. So:

- signing out deletes that session's row: a copy of the cookie taken before is refused;
- "sign out everywhere" renews the user's epoch: every session of theirs ends;
- a changed role or password renews the epoch too, by a trigger on `auth_users`, so a change made
  by `flask users ...` in another process counts the same as one made through the API;
- removing the user removes their epoch and sessions (ON DELETE CASCADE): a user re-created under
  the same name gets a new epoch, and the old cookie means nothing.

Streams opened with an API token carry the epoch too (auth/revocation.py): a token survives a
password change, the streams opened with it do not.
"""

from __future__ import annotations

import hashlib
import secrets
import time

from .accounts import TOKEN_PREFIX, token_digest
from .revocation import Credential

# Statements one by one: the trigger bodies hold semicolons, which Database.ensure_schema splits on.
SESSIONS_SCHEMA = (
    """CREATE TABLE IF NOT EXISTS auth_epochs (
        user_name TEXT PRIMARY KEY REFERENCES auth_users(name) ON DELETE CASCADE,
        epoch TEXT NOT NULL)""",
    """CREATE TABLE IF NOT EXISTS auth_sessions (
        id_sha256 TEXT PRIMARY KEY,
        user_name TEXT NOT NULL REFERENCES auth_users(name) ON DELETE CASCADE,
        epoch TEXT NOT NULL,
        created_at REAL NOT NULL,
        expires_at REAL NOT NULL)""",
    "CREATE INDEX IF NOT EXISTS auth_sessions_by_user ON auth_sessions(user_name)",
    """CREATE TRIGGER IF NOT EXISTS auth_epoch_of_new_user AFTER INSERT ON auth_users BEGIN
        INSERT OR REPLACE INTO auth_epochs (user_name, epoch) VALUES (NEW.name, lower(hex(randomblob(16))));
    END""",
    # A password hash re-made with new Argon2 parameters at sign-in counts as a change too: that
    # user's other sessions end once. SQL cannot tell it from a new password.
    """CREATE TRIGGER IF NOT EXISTS auth_epoch_renewed AFTER UPDATE OF role, password_hash ON auth_users
    WHEN OLD.role IS NOT NEW.role OR OLD.password_hash IS NOT NEW.password_hash BEGIN
        INSERT OR REPLACE INTO auth_epochs (user_name, epoch) VALUES (NEW.name, lower(hex(randomblob(16))));
        DELETE FROM auth_sessions WHERE user_name = NEW.name;
    END""",
    # Users made before these tables existed (by the CLI, or an older rover_web).
    "INSERT OR IGNORE INTO auth_epochs (user_name, epoch) SELECT name, lower(hex(randomblob(16))) FROM auth_users",
)

ENDED_EVERYWHERE = "role or password changed, or signed out everywhere"


def session_digest(session_id: str) -> str:
    return hashlib.sha256(session_id.encode("utf-8", "surrogatepass")).hexdigest()


def _new_epoch() -> str:
    return secrets.token_hex(16)


class Sessions:
    def __init__(self, db, lifetime_s: float):
        self._db = db
        self.lifetime_s = lifetime_s
        with db.transaction() as conn:
            for statement in SESSIONS_SCHEMA:
                conn.execute(statement)

    def start(self, user_name: str) -> tuple[str, Credential] | None:
        """A new session for the user: (the id for the cookie, its credential); None if the user is gone."""
        session_id = secrets.token_urlsafe(32)
        now = time.time()
        with self._db.transaction() as conn:
            conn.execute("DELETE FROM auth_sessions WHERE expires_at <= ?", (now,))  # keeps the table small
            row = conn.execute("SELECT u.role, e.epoch FROM auth_users u LEFT JOIN auth_epochs e "
                               "ON e.user_name = u.name WHERE u.name = ?", (user_name,)).fetchone()
            if row is None:
                return None
            epoch = row["epoch"]
            if epoch is None:
                epoch = _new_epoch()
                conn.execute("INSERT INTO auth_epochs (user_name, epoch) VALUES (?, ?)", (user_name, epoch))
            digest = session_digest(session_id)
            conn.execute("INSERT INTO auth_sessions (id_sha256, user_name, epoch, created_at, expires_at) "
                         "VALUES (?, ?, ?, ?, ?)", (digest, user_name, epoch, now, now + self.lifetime_s))
        return session_id, Credential(user_name, row["role"], epoch, "session", digest)

    def end(self, session_id: str) -> None:
        with self._db.transaction() as conn:
            conn.execute("DELETE FROM auth_sessions WHERE id_sha256 = ?", (session_digest(session_id),))

    def end_everywhere(self, user_name: str) -> None:
        """Every session of the user, and every stream opened with any of their credentials."""
        with self._db.transaction() as conn:
            conn.execute("UPDATE auth_epochs SET epoch = ? WHERE user_name = ?", (_new_epoch(), user_name))
            conn.execute("DELETE FROM auth_sessions WHERE user_name = ?", (user_name,))

    def for_session(self, session_id: str) -> Credential | None:
        if not isinstance(session_id, str) or len(session_id) > 100:
            return None
        digest = session_digest(session_id)
        row = self._db.connection().execute(
            "SELECT s.user_name, u.role, s.epoch FROM auth_sessions s "
            "JOIN auth_users u ON u.name = s.user_name JOIN auth_epochs e ON e.user_name = s.user_name "
            "WHERE s.id_sha256 = ? AND s.expires_at > ? AND s.epoch = e.epoch", (digest, time.time())).fetchone()
        return Credential(row["user_name"], row["role"], row["epoch"], "session", digest) if row else None

    def for_token(self, token: str) -> Credential | None:
        """The token's credential, if it is a live token (the same rules as Accounts.user_for_token)."""
        if not isinstance(token, str) or not token.startswith(TOKEN_PREFIX) or len(token) > 100:
            return None
        row = self._db.connection().execute(
            "SELECT t.id, u.name, u.role, e.epoch FROM auth_tokens t JOIN auth_users u ON u.name = t.user_name "
            "LEFT JOIN auth_epochs e ON e.user_name = u.name WHERE t.token_sha256 = ? AND t.revoked_at IS NULL",
            (token_digest(token),)).fetchone()
        if row is None:
            return None
        return Credential(row["name"], row["role"], row["epoch"] or "", "token", str(row["id"]))

    def ended(self, credential: Credential) -> str | None:
        """Why a credential no longer holds, or None while it does (auth/revocation.py asks)."""
        conn = self._db.connection()
        user = conn.execute("SELECT u.role, e.epoch FROM auth_users u LEFT JOIN auth_epochs e "
                            "ON e.user_name = u.name WHERE u.name = ?", (credential.user,)).fetchone()
        if user is None:
            return "user removed"
        if credential.via == "token":
            token = conn.execute("SELECT revoked_at FROM auth_tokens WHERE id = ? AND user_name = ?",
                                 (int(credential.key), credential.user)).fetchone()
            if token is None or token["revoked_at"] is not None:
                return "token revoked"
        else:
            session = conn.execute("SELECT expires_at FROM auth_sessions WHERE id_sha256 = ?",
                                   (credential.key,)).fetchone()
            if (user["epoch"] or "") != credential.epoch or user["role"] != credential.role:
                return ENDED_EVERYWHERE
            if session is None:
                return "signed out"
            if session["expires_at"] <= time.time():
                return "session expired"
        if (user["epoch"] or "") != credential.epoch or user["role"] != credential.role:
            return ENDED_EVERYWHERE
        return None
