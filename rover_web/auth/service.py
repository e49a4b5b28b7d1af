"""The auth feature's per-app object: accounts, sign-in throttling, and whether sign-in is on."""

from __future__ import annotations

import logging
import os
import secrets
from pathlib import Path

from rover_web.config import ConfigError

from .accounts import ARGON2_MEMORY_KIB, ARGON2_TIME_COST, DEFAULT_MAX_HASHING, Accounts, password_hasher
from .policy import sign_in_required
from .throttle import HashGate, SignInThrottle

log = logging.getLogger(__name__)

ADD_USER_HINT = "flask --app rover_web users add NAME --role admin"


class AuthService:
    def __init__(self, db, mode: str, listen_hosts: list[str], config: dict | None = None):
        self.accounts = accounts_for(db, config or {})
        self.throttle = SignInThrottle((config or {}).get("ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN", 20))
        self.mode = mode
        self.listen_hosts = listen_hosts
        self.required = sign_in_required(mode, listen_hosts)

    def check_startable(self) -> None:
        """Refuse to serve a network with sign-in required and nobody able to sign in."""
        if mode_note := self.startup_note():
            log.warning(mode_note)
        if self.required and self.accounts.count() == 0:
            where = (f"listening on {', '.join(self.listen_hosts)}" if self.listen_hosts else
                     "this server did not say where it listens: set ROVER_WEB_HOST to its address")
            other_way = ", or listen on 127.0.0.1 only" if self.mode == "auto" else ""
            raise ConfigError(f"sign-in is required (ROVER_WEB_AUTH={self.mode}, {where}) but no user "
                              f"exists: add one with `{ADD_USER_HINT}`{other_way}")

    def startup_note(self) -> str | None:
        if self.mode == "off":
            return ("ROVER_WEB_AUTH=off: anyone who can reach this server can drive the robot, take control "
                    "and release the e-stop")
        return None


def accounts_for(db, config) -> Accounts:
    """Accounts with the configured Argon2 parameters and hashing bound (the server and the CLI)."""
    hasher = password_hasher(config.get("ROVER_WEB_ARGON2_MEMORY_KIB", ARGON2_MEMORY_KIB),
                             config.get("ROVER_WEB_ARGON2_TIME_COST", ARGON2_TIME_COST))
    return Accounts(db, hasher, HashGate(config.get("ROVER_WEB_SIGNIN_MAX_HASHING", DEFAULT_MAX_HASHING)))


def secret_key(configured: str | None, instance_path: str) -> str:
    """The configured key, or one made once and kept (mode 0600) in the instance folder, so sessions
    survive a restart."""
    if configured:
        return configured
    path = Path(instance_path) / "secret_key"
    try:
        return path.read_text().strip()
    except FileNotFoundError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    key = secrets.token_hex(32)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # another process made it first: use theirs
        return path.read_text().strip()
    with os.fdopen(fd, "w") as f:
        f.write(key)
    return key
