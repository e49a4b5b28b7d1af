"""`flask --app rover_web link-emulator`: put an emulated field link in front of rover_web (no ROS)."""

from __future__ import annotations

import signal
import threading

import click
from flask import Flask

from .emulator import LinkEmulator, parse_address
from .profiles import PROFILES, profile


def _address(ctx, param, value):
    if value is None:
        return None
    try:
        return parse_address(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


def init_cli(app: Flask) -> None:
    @app.cli.command("link-emulator")
    @click.option("--profile", "name", type=click.Choice([*PROFILES, "custom"]), default="wifi-edge",
                  show_default=True, help="the link to emulate")
    @click.option("--listen", callback=_address, help="TCP address clients connect to, e.g. 127.0.0.1:8001")
    @click.option("--target", callback=_address, help="TCP address of the server, e.g. 127.0.0.1:5000")
    @click.option("--udp-listen", callback=_address, help="UDP address to relay from (one flow per client)")
    @click.option("--udp-target", callback=_address, help="UDP address to relay to")
    @click.option("--rate-kbps", type=float, help="bandwidth each way, kbit/s")
    @click.option("--delay-ms", type=float, help="one-way delay, ms")
    @click.option("--jitter-ms", type=float, help="one-way delay varies by ± this, ms")
    @click.option("--buffer-kb", type=float, help="the bottleneck's buffer, kB (deeper: more queueing delay)")
    @click.option("--loss", type=float, help="packet loss 0..1 (UDP drops; TCP retransmission delays)")
    @click.option("--stall-every-s", type=float, help="a stall about this often, s")
    @click.option("--stall-ms", type=float, help="how long a stall holds every byte, ms")
    @click.option("--outage-every-s", type=float, help="an outage this often, s")
    @click.option("--outage-s", type=float, help="how long nothing passes, s")
    @click.option("--reset-on-outage", is_flag=True, default=None, help="cut TCP connections when an outage starts")
    @click.option("--seed", type=int, default=None, help="random seed, for a repeatable run")
    @click.option("--report-s", type=click.FloatRange(0), default=10.0, show_default=True,
                  help="print the counters this often (0: never)")
    def link_emulator(name, listen, target, udp_listen, udp_target, report_s, seed, **overrides):
        """Relay TCP (and UDP) through an emulated field link: bandwidth, buffer, delay, jitter,
        loss, stalls and outages. Any of the numeric flags overrides the profile's value."""
        if (listen is None) != (target is None) or (udp_listen is None) != (udp_target is None) \
                or (listen is None and udp_listen is None):
            raise click.UsageError("give --listen with --target (and/or --udp-listen with --udp-target)")
        try:
            link = profile(name, **overrides)
        except (ValueError, TypeError) as exc:
            raise click.UsageError(str(exc)) from None
        emulator = LinkEmulator(link, listen, target, udp_listen=udp_listen, udp_target=udp_target, seed=seed)
        try:
            emulator.start()
        except OSError as exc:
            raise click.ClickException(f"cannot listen: {exc}") from None
        if emulator.address:
            click.echo(f"link-emulator: {link.describe()}; TCP {_show(emulator.address)} -> {_show(target)}")
        if emulator.udp_address:
            click.echo(f"link-emulator: UDP {_show(emulator.udp_address)} -> {_show(udp_target)}")
        click.echo(f"link-emulator: seed {emulator.seed}; Ctrl-C stops", err=True)
        stop = threading.Event()
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, lambda *_: stop.set())
        try:
            while not stop.wait(report_s or None):
                click.echo(_report(emulator.counters()), err=True)
        finally:
            emulator.stop()
        click.echo("link-emulator: stopped", err=True)


def _show(address) -> str:
    return f"{address[0]}:{address[1]}"


def _report(c: dict) -> str:
    return (f"up {c['up']['bytes_passed']} B passed, {c['up']['queue_bytes']} B queued; "
            f"down {c['down']['bytes_passed']} B passed, {c['down']['queue_bytes']} B queued; "
            f"dropped {c['up']['packets_dropped'] + c['down']['packets_dropped']} datagrams; "
            f"{c['stalls']} stalls, {c['outages']} outages, {c['connections']} connections open")
