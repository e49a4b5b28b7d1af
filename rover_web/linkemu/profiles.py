"""Named link profiles: what a boat's Wi-Fi, a long-range radio or a satellite link does to bytes.

Each direction (up: client → server, down: server → client) gets the same profile, as its own
bottleneck. The figures are the issue's (25); the buffer depths are ours: about a second of the
link's rate on the poor links (access points and radios with deep buffers, so bufferbloat shows)
and about 100 ms on the good ones.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace


@dataclass(frozen=True)
class Profile:
    name: str
    rate_kbps: float            # bandwidth cap, kbit/s of payload, each direction
    delay_ms: float             # one-way delay
    jitter_ms: float = 0.0      # one-way delay varies uniformly in delay ± jitter (never below 0)
    buffer_kb: float = 256.0    # the bottleneck's FIFO, in kB (1000 bytes): deeper means more queueing delay
    loss: float = 0.0           # packet loss, 0..1: UDP datagrams dropped; on TCP a lost segment costs a retransmission
    stall_every_s: float = 0.0  # a stall about this often (uniform in 0.5..1.5 × it); 0 = none
    stall_ms: float = 0.0       # ... holding every byte this long, as a TCP retransmission timeout does
    outage_every_s: float = 0.0  # an outage this often (the first at half the period); 0 = none
    outage_s: float = 0.0       # ... during which nothing passes
    reset_on_outage: bool = False  # TCP connections are reset when an outage starts (else bytes wait)

    def __post_init__(self) -> None:
        checks = {
            "rate_kbps": 1 <= self.rate_kbps <= 10_000_000,
            "delay_ms": 0 <= self.delay_ms <= 60_000,
            "jitter_ms": 0 <= self.jitter_ms <= 60_000,
            "buffer_kb": 1 <= self.buffer_kb <= 1_000_000,
            "loss": 0 <= self.loss < 1,
            "stall_every_s": 0 <= self.stall_every_s <= 86_400,
            "stall_ms": 0 <= self.stall_ms <= 600_000,
            "outage_every_s": 0 <= self.outage_every_s <= 86_400,
            "outage_s": 0 <= self.outage_s <= 86_400,
        }
        bad = [name for name, ok in checks.items() if not ok]
        if bad:
            raise ValueError(f"profile {self.name!r}: out of range: {', '.join(bad)}")
        if self.outage_every_s and self.outage_s >= self.outage_every_s:
            raise ValueError(f"profile {self.name!r}: an outage must be shorter than its period")

    @property
    def rate_bytes_per_s(self) -> float:
        return self.rate_kbps * 1000 / 8

    @property
    def buffer_bytes(self) -> int:
        return int(self.buffer_kb * 1000)

    @property
    def rtt_ms(self) -> float:
        """The nominal round trip: both one-way delays, no queueing."""
        return 2 * self.delay_ms

    def describe(self) -> str:
        parts = [f"{self.rate_kbps / 1000:g} Mbit/s", f"{self.delay_ms:g} ± {self.jitter_ms:g} ms",
                 f"buffer {self.buffer_kb:g} kB"]
        if self.loss:
            parts.append(f"{self.loss * 100:g} % loss")
        if self.stall_every_s and self.stall_ms:
            parts.append(f"{self.stall_ms:g} ms stall ~every {self.stall_every_s:g} s")
        if self.outage_every_s and self.outage_s:
            parts.append(f"{self.outage_s:g} s outage every {self.outage_every_s:g} s"
                         + (" (resets TCP)" if self.reset_on_outage else ""))
        return f"{self.name}: " + ", ".join(parts)


PROFILES: dict[str, Profile] = {p.name: p for p in (
    Profile("wifi-good", rate_kbps=20_000, delay_ms=10, jitter_ms=5, buffer_kb=256),
    Profile("wifi-edge", rate_kbps=2_000, delay_ms=60, jitter_ms=40, buffer_kb=256,
            stall_every_s=10, stall_ms=400),
    Profile("radio", rate_kbps=500, delay_ms=150, jitter_ms=50, buffer_kb=64,
            stall_every_s=15, stall_ms=500, outage_every_s=60, outage_s=3),
    Profile("starlink", rate_kbps=15_000, delay_ms=30, jitter_ms=10, buffer_kb=192, loss=0.02),
)}

CUSTOM_FIELDS = tuple(f.name for f in fields(Profile) if f.name != "name")


def profile(name: str, **overrides) -> Profile:
    """A named profile, with any field overridden; `custom` starts from a plain 10 Mbit/s link."""
    overrides = {k: v for k, v in overrides.items() if v is not None}
    if name == "custom":
        return Profile("custom", **{"rate_kbps": 10_000, "delay_ms": 0.0, **overrides})
    try:
        base = PROFILES[name]
    except KeyError:
        raise ValueError(f"unknown profile {name!r}: one of {', '.join([*PROFILES, 'custom'])}") from None
    return replace(base, **overrides) if overrides else base
