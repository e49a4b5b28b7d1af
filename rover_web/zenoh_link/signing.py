"""What proves a message came from the fleet: HMAC-SHA256 under the fleet's shared key. Pure Python.

Zenoh itself authenticates nobody unless its TLS and access control are configured
(docs/security.md#the-fleet-over-zenoh), so anyone on the Zenoh network could publish a summary
or ask a robot to stop. Each message therefore carries an HMAC over its fields, in a fixed
order, under the key every robot and the hub read from ROVER_WEB_FLEET_KEY_FILE:

- a stop command: (fleet, robot, nonce, timestamp, hub user). The robot refuses it when the
  timestamp is further than the window from its own clock, or when it has seen the nonce
  (ReplayGuard), so a recorded command cannot be played again;
- the robot's answer: (fleet, robot, nonce, result), so a hub believes "engaged" only from the
  robot it asked, for the command it sent;
- a summary: the bytes of its JSON envelope (fleet, robot, seq, sent, summary), checked before
  they are parsed, so a hub ignores forged ones at the cost of one HMAC.

The fields are joined as JSON (a list), which quotes every string: no two different tuples give
the same bytes, whatever a field contains.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import math
import os
import secrets
import stat
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path

from rover_web.config import ConfigError

MIN_KEY_BYTES = 32
NONCE_BYTES = 16
REPLAY_CACHE_MAX = 4096  # nonces kept; a full cache forgets its oldest (see ReplayGuard)
# A stop command or its answer is ~300 bytes; anything bigger is refused before it is parsed.
COMMAND_MAX_BYTES = 4096


def load_key(path: str | None) -> bytes:
    """The fleet key from ROVER_WEB_FLEET_KEY_FILE: surrounding whitespace dropped, 32 bytes or more,
    in a file only its owner may read and write."""
    if not path:
        raise ConfigError("ROVER_WEB_FLEET_KEY_FILE: the Zenoh link needs the fleet's shared key to sign and check "
                          "its messages: write 32+ random bytes to a file only you can read ((umask 077; python -c "
                          "\"import secrets; print(secrets.token_hex(32))\" > fleet.key)) on the hub and every "
                          "robot, and name it here")
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
        key = Path(path).read_bytes().strip()
    except OSError as exc:
        raise ConfigError(f"ROVER_WEB_FLEET_KEY_FILE: cannot read {path}: {exc.strerror}") from None
    if mode & 0o077:
        # Refused, not warned about as the database is: whoever reads this key can stop every robot
        # and forge their summaries (as ssh refuses a private key others can read).
        raise ConfigError(f"ROVER_WEB_FLEET_KEY_FILE: {path} may be read or written by others (mode {mode:o}): "
                          f"chmod 600 {path}; whoever holds the fleet key can stop every robot")
    if len(key) < MIN_KEY_BYTES:
        raise ConfigError(f"ROVER_WEB_FLEET_KEY_FILE: {path} holds {len(key)} bytes; the fleet key needs at least "
                          f"{MIN_KEY_BYTES} (a shorter one can be guessed offline from one signed message)")
    return key


def mac(key: bytes, *fields: object) -> str:
    return hmac.new(key, json.dumps(list(fields), separators=(",", ":")).encode(), hashlib.sha256).hexdigest()


def _same(expected: str, given: object) -> bool:
    return isinstance(given, str) and hmac.compare_digest(expected, given)


# --- stop commands ---

def stop_command(key: bytes, fleet: str, robot: str, by: str, now: float | None = None) -> dict:
    """The hub's signed request that `robot` engage its e-stop, for hub user `by`."""
    nonce = secrets.token_hex(NONCE_BYTES)
    ts = time.time() if now is None else now
    return {"fleet": fleet, "robot": robot, "nonce": nonce, "ts": ts, "by": by,
            "sig": mac(key, "stop", fleet, robot, nonce, ts, by)}


class CommandRefused(Exception):
    """A stop command the robot will not act on; `reason` is the answer's code."""

    def __init__(self, reason: str, message: str):
        super().__init__(message)
        self.reason = reason


class ReplayGuard:
    """Nonces seen within the time window, so each signed command acts once.

    Bounded in time (a nonce is forgotten once its command is outside the window, and would be
    refused as stale anyway) and in size (REPLAY_CACHE_MAX). Only commands whose signature
    checked are recorded, so filling the cache needs the fleet key; when it is full the oldest
    nonce is forgotten, which can let that one command, replayed within its window, stop the
    robot a second time: the one harm a replay can do here.
    """

    def __init__(self, window_s: float, max_entries: int = REPLAY_CACHE_MAX, clock: Callable[[], float] = time.time):
        self.window_s = window_s
        self.max_entries = max_entries
        self._clock = clock
        self._seen: OrderedDict[str, float] = OrderedDict()  # nonce -> when it may be forgotten
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._seen)

    def check(self, key: bytes, fleet: str, robot: str, command: object) -> dict:
        """The command if it is authentic, meant for this robot, fresh and new; CommandRefused otherwise."""
        if not isinstance(command, dict):
            raise CommandRefused("malformed", "the command is not a JSON object")
        nonce, ts, by = command.get("nonce"), command.get("ts"), command.get("by")
        if (not isinstance(nonce, str) or not 16 <= len(nonce) <= 128 or not isinstance(by, str) or len(by) > 80
                or isinstance(ts, bool) or not isinstance(ts, (int, float))):
            raise CommandRefused("malformed", "the command lacks a nonce, a timestamp or a user")
        if command.get("fleet") != fleet or command.get("robot") != robot:
            raise CommandRefused("wrong_robot", f"the command is for {command.get('robot')!r} of "
                                 f"{command.get('fleet')!r}, not {robot!r} of {fleet!r}")
        if not _same(mac(key, "stop", fleet, robot, nonce, ts, by), command.get("sig")):
            raise CommandRefused("bad_signature", "the command's signature does not check with this fleet's key")
        now = self._clock()
        if abs(now - ts) > self.window_s:
            raise CommandRefused("stale", f"the command's timestamp is {now - ts:+.1f} s from this robot's clock "
                                 f"(at most {self.window_s:g} s either way)")
        with self._lock:
            self._forget_expired(now)
            if nonce in self._seen:
                raise CommandRefused("replayed", "this command was already received")
            if len(self._seen) >= self.max_entries:
                self._seen.popitem(last=False)
            self._seen[nonce] = max(now, ts) + self.window_s
        return command

    def _forget_expired(self, now: float) -> None:
        # Insertion order is close to expiry order (timestamps within the window): stop at the first live one.
        while self._seen:
            nonce, expires = next(iter(self._seen.items()))
            if expires > now:
                break
            del self._seen[nonce]


# --- answers to a stop ---

def answer(key: bytes, fleet: str, robot: str, nonce: str, result: str, **extra: object) -> dict:
    return {"fleet": fleet, "robot": robot, "nonce": nonce, "result": result, **extra,
            "sig": mac(key, "answer", fleet, robot, nonce, result)}


def answer_checks(key: bytes, command: dict, reply: object) -> bool:
    """Whether `reply` is the robot's own signed answer to `command`."""
    return (isinstance(reply, dict) and reply.get("robot") == command["robot"]
            and reply.get("nonce") == command["nonce"] and isinstance(reply.get("result"), str)
            and _same(mac(key, "answer", command["fleet"], command["robot"], command["nonce"], reply["result"]),
                      reply.get("sig")))


# --- summaries ---
# A summary travels as b"rws1." + HMAC hex + b"." + the envelope's JSON, the MAC over those JSON
# bytes: the hub checks the signature on the raw bytes before any JSON parser sees them, and
# refuses an oversized payload before both (anyone on the Zenoh network can publish; a forged
# 50 MB summary cost 0.34 s of parsing when the signature sat inside the JSON). Issue 40.

SUMMARY_MAGIC = b"rws1."
SUMMARY_MAX_BYTES = 64 * 1024  # a robot's line is about 1 kB; its alerts are bounded by the geofence's message


def _summary_mac(key: bytes, envelope: bytes) -> bytes:
    return hmac.new(key, b"rover_web summary\n" + envelope, hashlib.sha256).hexdigest().encode()


def signed_summary(key: bytes, fleet: str, robot: str, seq: int, summary: dict, now: float | None = None) -> bytes:
    sent = time.time() if now is None else now
    envelope = json.dumps({"fleet": fleet, "robot": robot, "seq": seq, "sent": sent, "summary": summary},
                          separators=(",", ":"), sort_keys=True).encode()
    return SUMMARY_MAGIC + _summary_mac(key, envelope) + b"." + envelope


def open_summary(key: bytes, fleet: str, payload: bytes) -> dict | None:
    """(robot, seq, sent, summary) of an authentic summary of `fleet`, as a dict; None for anything else.

    Nothing is parsed before the size and the signature check."""
    if len(payload) > SUMMARY_MAX_BYTES or not payload.startswith(SUMMARY_MAGIC):
        return None
    sig, dot, envelope = payload[len(SUMMARY_MAGIC):].partition(b".")
    if not dot or not hmac.compare_digest(_summary_mac(key, envelope), sig):
        return None
    try:
        opened = json.loads(envelope)
    except ValueError:
        return None
    if not isinstance(opened, dict) or opened.get("fleet") != fleet:
        return None
    robot, seq, sent, summary = opened.get("robot"), opened.get("seq"), opened.get("sent"), opened.get("summary")
    if not isinstance(robot, str) or not isinstance(summary, dict) or isinstance(sent, bool) \
            or not isinstance(sent, (int, float)) or not math.isfinite(sent):
        return None
    return {"robot": robot, "seq": seq, "sent": sent, "summary": summary}
