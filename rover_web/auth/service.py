"""The auth feature's per-app object: accounts, sessions, revocation, sign-in throttling, and
whether sign-in is on (for the server, and for each request under `auto`)."""

from __future__ import annotations

import logging
import os
import secrets
from pathlib import Path

from flask import g

from rover_web.config import ConfigError
from rover_web.web.api_messages import explain

from .accounts import ARGON2_MEMORY_KIB, ARGON2_TIME_COST, DEFAULT_MAX_HASHING, Accounts, password_hasher
from .policy import exposed_host, forwarded_header, is_loopback, sign_in_required
from .revocation import CHECK_PERIOD_S, Revocations
from .sessions import Sessions
from .throttle import HashGate, SignInThrottle

log = logging.getLogger(__name__)

ADD_USER_HINT = "flask --app rover_web users add NAME --role admin"
MIN_SECRET_KEY_BYTES = 32  # HMAC-SHA1 under Flask's signer: a shorter key can be guessed offline from one cookie


class AuthService:
    def __init__(self, db, mode: str, listen_hosts: list[str], config: dict | None = None, *,
                 session_hours: float = 12.0, trusted_hosts: list[str] = ()):
        self.accounts = accounts_for(db, config or {})
        self.throttle = SignInThrottle((config or {}).get("ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN", 20))
        self.sessions = Sessions(db, session_hours * 3600.0)
        self.revocations = Revocations(self.sessions.ended)
        self.mode = mode
        self.listen_hosts = listen_hosts
        self.trusted_hosts = list(trusted_hosts)
        self.required = sign_in_required(mode, listen_hosts)
        self.proxy_hops = (config or {}).get("ROVER_WEB_PROXY_HOPS", 0)

    def start(self, rover) -> None:
        """The backstop: changes made in another process (the CLI) reach open streams within a
        second. Asleep while nothing is registered."""
        rover.every(CHECK_PERIOD_S, self.revocations.check, name="auth-revocation",
                    only_while=self.revocations.any_open)

    # --- per request ---

    def exposure(self, req) -> str | None:
        """Why a request to a server with sign-in off under `auto` came from beyond this machine:
        a proxy's forwarding header, or a Host that is not loopback. None otherwise."""
        if self.required or self.mode != "auto":
            return None
        header = forwarded_header(req.headers)
        if header:
            return explain("it came through a proxy (%(header)s)", header=header)
        host = exposed_host(req.host)
        if host:
            return explain("it asked for the host %(host)s", host=repr(host[:80]))
        return None

    def sign_in_on(self) -> bool:
        """Whether the current request must be signed in (decided once per request by check_access)."""
        return g.get("rover_web_sign_in", self.required)

    def revoked(self) -> int:
        """Call after a credential changed in the database: open streams of ended ones close now."""
        return self.revocations.check()

    # --- at start ---

    def check_startable(self) -> None:
        """Refuse to serve a network with sign-in required and nobody able to sign in."""
        if mode_note := self.startup_note():
            log.warning(mode_note)
        if self.proxy_hops and not (self.listen_hosts and all(is_loopback(h) for h in self.listen_hosts)):
            # A client that reaches the app around the proxy writes X-Forwarded-For itself.
            log.warning("ROVER_WEB_PROXY_HOPS=%d believes X-Forwarded-For from any client, and this server "
                        "may be reachable by others directly: listen on 127.0.0.1 behind the proxy, or "
                        "firewall the port, or per-address limits can be dodged", self.proxy_hops)
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
        if self.mode == "auto" and not self.required:
            names = [h for h in self.trusted_hosts if not is_loopback(h)]
            also = (f"; ROVER_WEB_TRUSTED_HOSTS names {', '.join(names)}, which would mean a proxy serves it"
                    if names else "")
            return ("ROVER_WEB_AUTH=auto and this server listens on loopback only: sign-in is off for requests "
                    "made on this machine, and the users and tokens API is refused. A request through a proxy "
                    "(X-Forwarded-* or Forwarded headers) or by another host name must sign in; behind a proxy, "
                    f"set ROVER_WEB_AUTH=required{also}")
        return None


def accounts_for(db, config) -> Accounts:
    """Accounts with the configured Argon2 parameters and hashing bound (the server and the CLI)."""
    hasher = password_hasher(config.get("ROVER_WEB_ARGON2_MEMORY_KIB", ARGON2_MEMORY_KIB),
                             config.get("ROVER_WEB_ARGON2_TIME_COST", ARGON2_TIME_COST))
    return Accounts(db, hasher, HashGate(config.get("ROVER_WEB_SIGNIN_MAX_HASHING", DEFAULT_MAX_HASHING)))


def secret_key(configured: str | None, instance_path: str) -> str:
    """The configured key, or one made once and kept (mode 0600) in the instance folder, so sessions
    survive a restart. A key shorter than 32 bytes is refused: it signs every session cookie."""
    if configured is not None:
        return _long_enough(configured, "ROVER_WEB_SECRET_KEY")
    path = Path(instance_path) / "secret_key"
    try:
        return _long_enough(path.read_text().strip(), str(path))
    except FileNotFoundError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    key = secrets.token_hex(32)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # another process made it first: use theirs
        return _long_enough(path.read_text().strip(), str(path))
    with os.fdopen(fd, "w") as f:
        f.write(key)
    return key


def _long_enough(key: str, where: str) -> str:
    size = len(key.encode("utf-8", "surrogatepass"))
    if size < MIN_SECRET_KEY_BYTES:
        raise ConfigError(f"{where} is {size} bytes; a key that signs session cookies needs at least "
                          f"{MIN_SECRET_KEY_BYTES} random bytes: make one with "
                          "`python3 -c 'import secrets; print(secrets.token_hex(32))'`, or leave "
                          "ROVER_WEB_SECRET_KEY unset to have one made and kept in the instance folder")
    return key
