"""Which addresses ICE may use: the settings' ICE servers only, and host candidates on chosen addresses.

aioice gathers a host candidate on every address of every interface (`aioice.ice.get_host_addresses`,
which also leaves out 127.0.0.1), and aiortc has no option to choose them. A robot's server may
want only its radio's address offered, and tests and benches must keep every packet on 127.0.0.1.
So `only_host_addresses(addresses)` sets a context variable that our wrapper of that one aioice
function reads: asyncio tasks inherit context variables, so a peer connection whose local
description is set inside `with only_host_addresses(...)` gathers (and binds UDP sockets) on those
addresses alone, while other code in the same process (another app, a test client) keeps its own.
`filter_candidates` then drops any other candidate from the answer, as a second guard.
`host_addresses(config)` is which addresses those are (the setting's, or 127.0.0.1 for a server that
listens on loopback only), and `without_mdns` drops an offer's `.local` candidates.
Pure Python apart from the aioice import.
"""

from __future__ import annotations

import contextlib
import contextvars
import ipaddress
import re
from collections.abc import Iterable, Iterator

from rover_web import process
from rover_web.auth.policy import is_loopback
from rover_web.config import ConfigError

_HOST_ADDRESSES: contextvars.ContextVar[tuple[str, ...] | None] = contextvars.ContextVar(
    "rover_web_webrtc_host_addresses", default=None)
_original_get_host_addresses = None


def _get_host_addresses(use_ipv4: bool, use_ipv6: bool) -> list[str]:
    chosen = _HOST_ADDRESSES.get()
    if chosen is None:
        return _original_get_host_addresses(use_ipv4, use_ipv6)
    return [a for a in chosen if (use_ipv4 and ":" not in a) or (use_ipv6 and ":" in a)]


def _install() -> None:
    """Wrap aioice's address lookup (see the module's docstring), on the first gathering: aioice
    is imported only when a WebRTC session is first offered (service.py says why)."""
    global _original_get_host_addresses
    import aioice.ice

    if getattr(aioice.ice.get_host_addresses, "__module__", "") != __name__:
        _original_get_host_addresses = aioice.ice.get_host_addresses
        aioice.ice.get_host_addresses = _get_host_addresses


def check_addresses(addresses: Iterable[str]) -> tuple[str, ...]:
    """IP literals only (ValueError otherwise): a name would need a DNS lookup at gather time."""
    out = []
    for address in addresses:
        out.append(str(ipaddress.ip_address(address.strip())))
    return tuple(out)


@contextlib.contextmanager
def only_host_addresses(addresses: Iterable[str] | None) -> Iterator[None]:
    """Within this block (and tasks started in it), gather host candidates on `addresses` only;
    None or empty: every interface, as aioice does by itself."""
    _install()
    chosen = tuple(addresses) if addresses else None
    token = _HOST_ADDRESSES.set(chosen)
    try:
        yield
    finally:
        _HOST_ADDRESSES.reset(token)


_CANDIDATE = re.compile(r"^a=candidate:\S+ \d+ \S+ \d+ (\S+) \d+ typ (\S+)")


def candidate_address(line: str) -> tuple[str, str] | None:
    """(address, type) of an `a=candidate:` line, None for any other line."""
    match = _CANDIDATE.match(line.strip())
    return (match.group(1), match.group(2)) if match else None


def filter_candidates(sdp: str, allowed: Iterable[str] | None) -> str:
    """The SDP without host candidates on addresses outside `allowed` (all kept when it is empty).
    Relay and reflexive candidates stay: they only exist when the settings name an ICE server."""
    allowed_set = set(allowed or ())
    if not allowed_set:
        return sdp
    kept = []
    for line in sdp.splitlines():
        found = candidate_address(line)
        if found and found[1] == "host" and found[0] not in allowed_set:
            continue
        kept.append(line)
    return "\r\n".join(kept) + "\r\n"


MAX_REMOTE_CANDIDATES = 12  # a browser on wifi and cellular, IPv4 and IPv6, host and reflexive: under 10
_REMOTE = re.compile(r"^a=candidate:\S+ \d+ \S+ \d+ (\S+) (\d+) typ ")


def unusable_remote(address: str, port: int) -> str | None:
    """Why a remote candidate is not worth a connectivity check (each costs STUN requests to a place
    the client chose: the review's 300 candidates made 1,428), or None."""
    if port == 0 or port < 1024:
        return "port"
    try:
        ip = ipaddress.ip_address(address)
    except ValueError:
        return "name"  # not an IP literal: resolving it would be a DNS query the client chose (.local: mDNS)
    if ip.is_multicast or ip.is_unspecified:
        return "multicast" if ip.is_multicast else "unspecified"
    if ip.version == 4 and (ip == ipaddress.IPv4Address("255.255.255.255") or address.endswith(".255")):
        return "broadcast"  # the limited broadcast, and the usual /24's directed one
    return None


def screen_remote_candidates(offer: str) -> tuple[str, int, int]:
    """The offer with at most MAX_REMOTE_CANDIDATES usable candidates, the others dropped:
    (offer, kept, dropped)."""
    lines = offer.split("\n")
    kept_lines, kept, dropped = [], 0, 0
    for line in lines:
        match = _REMOTE.match(line.strip())
        if match:
            if kept >= MAX_REMOTE_CANDIDATES or unusable_remote(match.group(1), int(match.group(2))):
                dropped += 1
                continue
            kept += 1
        kept_lines.append(line)
    return "\n".join(kept_lines), kept, dropped


def candidates(sdp: str) -> list[tuple[str, str]]:
    return [found for line in sdp.splitlines() if (found := candidate_address(line))]


_ICE_URL = re.compile(r"(stun|stuns|turn|turns):(?:(?P<user>[^:@/]+):(?P<secret>[^@/]+)@)?(?P<rest>[^@/\s]+)")


def parse_ice_server(text: str) -> dict:
    """A setting entry `stun:host:port` or `turn:user:secret@host:port[?transport=udp]` as
    RTCIceServer arguments; ValueError for anything else."""
    match = _ICE_URL.fullmatch(text.strip())
    if not match:
        raise ValueError(f"{text[:80]!r} is not an ICE server: use stun:host:port or turn:user:secret@host:port")
    url = f"{match.group(1)}:{match.group('rest')}"
    server = {"urls": url}
    if match.group("user"):
        server.update(username=match.group("user"), credential=match.group("secret"))
    elif match.group(1).startswith("turn"):
        raise ValueError(f"{text[:80]!r}: a TURN server needs credentials (turn:user:secret@host:port)")
    return server


def host_addresses(config) -> tuple[str, ...]:
    """The setting's addresses; when it is empty and the server listens on loopback only, 127.0.0.1
    (nobody elsewhere can reach the page, so no other address is worth offering: the tests rely on
    this); else () for every interface's."""
    try:
        chosen = check_addresses(config["ROVER_WEB_WEBRTC_HOST_ADDRESSES"])
    except ValueError as exc:
        raise ConfigError(f"ROVER_WEB_WEBRTC_HOST_ADDRESSES: {exc}") from None
    if chosen:
        return chosen
    listening = process.listen_hosts(config)
    if listening and all(is_loopback(h) for h in listening):
        return ("127.0.0.1",)
    return ()


def without_mdns(offer: str) -> str:
    """Drop the offer's mDNS (`.local`) candidates: resolving them would send multicast queries on
    every interface. A browser behind one is found anyway, from its connectivity checks (a
    peer-reflexive candidate)."""
    lines = offer.split("\n")
    kept = [line for line in lines if not ((found := candidate_address(line)) and found[0].endswith(".local"))]
    return "\n".join(kept)
