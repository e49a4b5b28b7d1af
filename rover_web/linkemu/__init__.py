"""An emulated field link in user space (this kernel has no netem): `flask --app rover_web
link-emulator`, or LinkEmulator in tests and bench/link.py.

Modules: profiles (the named links and their figures), bottleneck (the scheduling maths: a shared
FIFO at a rate, delay and jitter, loss, stalls and outages; no sockets, any clock), direction (a
bottleneck driven by asyncio), tcp and udp (the relays), emulator (LinkEmulator: its loop on a
thread, live controls, counters), cli (the flask command, registered before and without ROS).
"""

from __future__ import annotations

from .cli import init_cli
from .emulator import LinkEmulator, parse_address
from .profiles import PROFILES, Profile, profile

__all__ = ["LinkEmulator", "PROFILES", "Profile", "init_cli", "parse_address", "profile"]
