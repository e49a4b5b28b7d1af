"""Users, their roles and their API tokens, kept in the app's SQLite database.

Passwords are hashed with Argon2id (argon2-cffi: memory-hard, salted, parameters stored in the hash,
so they can be changed later and old hashes re-hashed on sign-in). The parameters are OWASP's for a
small computer (19 MiB, 2 passes, 1 lane) rather than argon2-cffi's default (64 MiB, 3 passes,
4 lanes): a robot's computer has little memory, and every hash runs under a `HashGate` slot.
API tokens are random 256-bit strings shown once; only their SHA-256 is stored: a token is already
high-entropy, so a slow hash would only cost every curl request time without adding strength (and a
token check takes no hashing slot).
"""

from __future__ import annotations

import functools
import hashlib
import hmac
import re
import secrets
import sqlite3
import time
from dataclasses import dataclass

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError

from rover_web.web.api_messages import explain

from .throttle import HashGate, HashingBusy

ROLES = ("viewer", "operator", "admin")
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.@-]{0,39}\Z")
MIN_PASSWORD_LEN = 8
MAX_PASSWORD_LEN = 1024  # argon2 takes any length; a megabyte "password" would only cost CPU
TOKEN_PREFIX = "rwt_"
SQLITE_MAX_INT = (1 << 63) - 1  # the largest id a row can have

ACCOUNTS_DDL = """
CREATE TABLE IF NOT EXISTS auth_users (
    name TEXT PRIMARY KEY CHECK (length(name) BETWEEN 1 AND 40),
    role TEXT NOT NULL CHECK (role IN ('viewer', 'operator', 'admin')),
    password_hash TEXT NOT NULL,
    created_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS auth_tokens (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    user_name TEXT NOT NULL REFERENCES auth_users(name) ON DELETE CASCADE,
    token_sha256 TEXT NOT NULL UNIQUE,
    label TEXT NOT NULL DEFAULT '' CHECK (length(label) <= 80),
    created_at REAL NOT NULL,
    revoked_at REAL
)
"""

# OWASP Password Storage Cheat Sheet, Argon2id: m=19 MiB, t=2, p=1 (or m=12 MiB, t=3).
ARGON2_MEMORY_KIB = 19 * 1024
ARGON2_TIME_COST = 2
ARGON2_PARALLELISM = 1  # one lane: a sign-in never takes more than one core
DEFAULT_MAX_HASHING = 2

__all__ = ["Accounts", "AccountError", "HashingBusy", "User", "password_hasher"]


def password_hasher(memory_kib: int = ARGON2_MEMORY_KIB, time_cost: int = ARGON2_TIME_COST) -> PasswordHasher:
    return PasswordHasher(time_cost=time_cost, memory_cost=memory_kib, parallelism=ARGON2_PARALLELISM)


@functools.cache
def _dummy_hash(hasher: PasswordHasher) -> str:
    """A hash of a password nobody has, checked when the name is unknown, so that an unknown name
    takes as long to refuse as a wrong password (no user enumeration by timing). Made at the first
    sign-in, not at start: an Argon2 hash takes megabytes and tens of milliseconds."""
    return hasher.hash(secrets.token_hex(16))


class AccountError(ValueError):
    """A request about accounts that cannot be done; the message says why."""

    def __init__(self, message: str, code: str = "bad_value"):
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class User:
    name: str
    role: str

    def may(self, role: str) -> bool:
        """True when this user's role includes `role` (admin > operator > viewer)."""
        return ROLES.index(self.role) >= ROLES.index(role)


def check_name(name: str) -> str:
    if not isinstance(name, str) or not NAME_PATTERN.match(name):
        raise AccountError(explain("a user name is 1-40 letters, digits, '_', '.', '@' or '-', starting with a "
                                   "letter or digit"), "bad_name")
    return name


def check_role(role: str) -> str:
    if role not in ROLES:
        raise AccountError(explain("role must be one of %(roles)s", roles=', '.join(ROLES)), "bad_role")
    return role


def check_password(password: str) -> str:
    if not isinstance(password, str) or not MIN_PASSWORD_LEN <= len(password) <= MAX_PASSWORD_LEN:
        raise AccountError(
            explain(
                "a password is %(min_password_len)s to %(max_password_len)s characters",
                min_password_len=MIN_PASSWORD_LEN,
                max_password_len=MAX_PASSWORD_LEN,
            ),
            "bad_password",
        )
    return password


def token_digest(token: str) -> str:
    return hashlib.sha256(token.encode("utf-8", "surrogatepass")).hexdigest()


class Accounts:
    def __init__(self, db, hasher: PasswordHasher | None = None, gate: HashGate | None = None):
        self._db = db
        self._hasher = hasher or password_hasher()
        self.gate = gate or HashGate(DEFAULT_MAX_HASHING)
        db.ensure_schema(ACCOUNTS_DDL)

    def _hash(self, password: str) -> str:
        # Admin work (the admin API, the CLI) waits for a slot rather than failing.
        return self.gate.run(self._hasher.hash, password, wait=True)

    def add_user(self, name: str, role: str, password: str) -> User:
        check_name(name), check_role(role), check_password(password)
        password_hash = self._hash(password)
        try:
            with self._db.transaction() as conn:
                conn.execute("INSERT INTO auth_users (name, role, password_hash, created_at) VALUES (?, ?, ?, ?)",
                             (name, role, password_hash, time.time()))
        except sqlite3.IntegrityError:
            raise AccountError(explain("user %(name)s exists already", name=repr(name)), "user_exists") from None
        return User(name, role)

    def users(self) -> list[dict]:
        rows = self._db.connection().execute(
            "SELECT u.name, u.role, u.created_at, "
            "(SELECT count(*) FROM auth_tokens t WHERE t.user_name = u.name AND t.revoked_at IS NULL) AS tokens "
            "FROM auth_users u ORDER BY u.name").fetchall()
        return [dict(row) for row in rows]

    def count(self) -> int:
        return self._db.connection().execute("SELECT count(*) FROM auth_users").fetchone()[0]

    def get(self, name: str) -> User | None:
        row = self._db.connection().execute("SELECT name, role FROM auth_users WHERE name = ?", (name,)).fetchone()
        return User(row["name"], row["role"]) if row else None

    def set_role(self, name: str, role: str) -> User:
        check_role(role)
        with self._db.transaction() as conn:
            if conn.execute("UPDATE auth_users SET role = ? WHERE name = ?", (role, name)).rowcount == 0:
                raise AccountError(explain("no user %(name)s", name=repr(name)), "no_such_user")
        return User(name, role)

    def set_password(self, name: str, password: str) -> None:
        check_password(password)
        password_hash = self._hash(password)
        with self._db.transaction() as conn:
            if conn.execute("UPDATE auth_users SET password_hash = ? WHERE name = ?",
                            (password_hash, name)).rowcount == 0:
                raise AccountError(explain("no user %(name)s", name=repr(name)), "no_such_user")

    def remove_user(self, name: str) -> None:
        """Removes the user and, with them, their tokens (ON DELETE CASCADE)."""
        with self._db.transaction() as conn:
            if conn.execute("DELETE FROM auth_users WHERE name = ?", (name,)).rowcount == 0:
                raise AccountError(explain("no user %(name)s", name=repr(name)), "no_such_user")

    def authenticate(self, name: str, password: str) -> User | None:
        """The user, if the password is theirs; None otherwise (same time either way).

        HashingBusy, before any hash is computed, when every hashing slot is taken. A hash made
        with other parameters (argon2-cffi's old default of 64 MiB, say) still verifies, and is
        replaced by one with the current parameters, in the same slot.
        """
        if not isinstance(name, str) or not isinstance(password, str) or len(password) > MAX_PASSWORD_LEN:
            return None
        row = self._db.connection().execute(
            "SELECT name, role, password_hash FROM auth_users WHERE name = ?", (name,)).fetchone()
        stored = row["password_hash"] if row else None

        def check() -> tuple[bool, str | None]:  # on a hashing thread: (verified, a new hash or None)
            try:
                self._hasher.verify(stored or _dummy_hash(self._hasher), password)
            except (VerificationError, InvalidHashError):
                return False, None
            if stored is not None and self._hasher.check_needs_rehash(stored):
                return True, self._hasher.hash(password)
            return True, None

        verified, new_hash = self.gate.run(check)
        if not verified or row is None:
            return None
        if new_hash is not None:
            with self._db.transaction() as conn:
                conn.execute("UPDATE auth_users SET password_hash = ? WHERE name = ? AND password_hash = ?",
                             (new_hash, name, stored))
        return User(row["name"], row["role"])

    # --- API tokens ---

    def create_token(self, user_name: str, label: str = "") -> tuple[int, str]:
        """A new token for the user: (its id, the token). The token is not stored and cannot be shown again."""
        if len(label) > 80:
            raise AccountError(explain("a token label is at most 80 characters"), "bad_label")
        token = TOKEN_PREFIX + secrets.token_urlsafe(32)
        with self._db.transaction() as conn:
            if conn.execute("SELECT 1 FROM auth_users WHERE name = ?", (user_name,)).fetchone() is None:
                raise AccountError(explain("no user %(user_name)s", user_name=repr(user_name)), "no_such_user")
            cursor = conn.execute(
                "INSERT INTO auth_tokens (user_name, token_sha256, label, created_at) VALUES (?, ?, ?, ?)",
                (user_name, token_digest(token), label, time.time()))
        return cursor.lastrowid, token

    def tokens(self) -> list[dict]:
        rows = self._db.connection().execute(
            "SELECT id, user_name AS user, label, created_at, revoked_at FROM auth_tokens ORDER BY id").fetchall()
        return [dict(row) for row in rows]

    def revoke_token(self, token_id: int) -> None:
        if not 0 <= token_id <= SQLITE_MAX_INT:  # SQLite cannot even compare a larger integer
            raise AccountError(explain("no token with id %(token_id)s", token_id=str(token_id)[:30]), "no_such_token")
        with self._db.transaction() as conn:
            row = conn.execute("SELECT revoked_at FROM auth_tokens WHERE id = ?", (token_id,)).fetchone()
            if row is None:
                raise AccountError(explain("no token with id %(token_id)s", token_id=token_id), "no_such_token")
            if row["revoked_at"] is None:
                conn.execute("UPDATE auth_tokens SET revoked_at = ? WHERE id = ?", (time.time(), token_id))

    def user_for_token(self, token: str) -> User | None:
        if not isinstance(token, str) or not token.startswith(TOKEN_PREFIX) or len(token) > 100:
            return None
        digest = token_digest(token)
        row = self._db.connection().execute(
            "SELECT u.name, u.role, t.token_sha256 FROM auth_tokens t JOIN auth_users u ON u.name = t.user_name "
            "WHERE t.token_sha256 = ? AND t.revoked_at IS NULL", (digest,)).fetchone()
        if row is None or not hmac.compare_digest(row["token_sha256"], digest):
            return None
        return User(row["name"], row["role"])
