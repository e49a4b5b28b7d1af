"""Real bytes through the link emulator on 127.0.0.1: the cap, the delay, outages, the shared
bottleneck, backpressure, UDP loss and outages, and the flask command. Assertions are on bounds
the emulator enforces (it can never be faster than its cap or its delay) and on orders of
magnitude, never on precise timings: the machine is shared."""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rover_web.linkemu import LinkEmulator, profile
from tests.support.waiting import wait_until

ROOT = Path(__file__).resolve().parents[3]


class TcpPeer:
    """A server on 127.0.0.1: echoes (echo=True) or counts what it receives, per connection."""

    def __init__(self, echo: bool = False):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.address = self.sock.getsockname()
        self.echo = echo
        self.received: list[int] = []  # bytes per connection, in accept order
        self.conns: list[socket.socket] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            with self._lock:
                index = len(self.received)
                self.received.append(0)
                self.conns.append(conn)
            threading.Thread(target=self._serve, args=(conn, index), daemon=True).start()

    def _serve(self, conn: socket.socket, index: int) -> None:
        with contextlib.suppress(OSError):
            while data := conn.recv(65536):
                with self._lock:
                    self.received[index] += len(data)
                if self.echo:
                    conn.sendall(data)

    def close(self) -> None:
        self.sock.close()
        for conn in self.conns:
            conn.close()


@pytest.fixture
def peer():
    made = []

    def make(**kwargs) -> TcpPeer:
        made.append(TcpPeer(**kwargs))
        return made[-1]
    yield make
    for p in made:
        p.close()


def recv_exactly(sock: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return data


def test_throughput_is_capped_near_the_rate(peer):
    sink = peer()
    link = profile("custom", rate_kbps=4000, delay_ms=5, buffer_kb=64)  # 500 kB/s
    size = 1_000_000
    with LinkEmulator(link, "127.0.0.1:0", sink.address) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        t0 = time.monotonic()
        client.sendall(b"x" * size)
        wait_until(lambda: sink.received and sink.received[0] == size, timeout=30, what="all bytes through")
        elapsed = time.monotonic() - t0
        counters = emu.counters()
    assert elapsed >= 0.9 * size / 500_000  # never faster than the cap
    assert elapsed < 8 * size / 500_000  # and of its order, even on a loaded machine
    assert counters["up"]["bytes_passed"] == size and counters["up"]["queue_peak"] <= 64_000


def test_a_round_trip_takes_the_delay_both_ways(peer):
    echo = peer(echo=True)
    link = profile("custom", rate_kbps=10_000, delay_ms=80, jitter_ms=10)
    with LinkEmulator(link, "127.0.0.1:0", echo.address, seed=1) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        rtts = []
        for i in range(5):
            t0 = time.monotonic()
            client.sendall(bytes([i]) * 10)
            assert recv_exactly(client, 10) == bytes([i]) * 10
            rtts.append(time.monotonic() - t0)
    assert min(rtts) >= 2 * 0.070  # each way at least delay - jitter
    assert sorted(rtts)[2] < 2 * 0.090 + 0.5


def test_an_outage_holds_bytes_then_they_flow(peer):
    echo = peer(echo=True)
    with LinkEmulator(profile("custom", delay_ms=5), "127.0.0.1:0", echo.address) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        client.sendall(b"before")
        assert recv_exactly(client, 6) == b"before"
        emu.outage(2.5)
        client.sendall(b"during")
        client.settimeout(0.5)
        with pytest.raises(TimeoutError):
            client.recv(10)  # nothing passes
        assert emu.counters()["up"]["bytes_passed"] == 6
        client.settimeout(15)
        assert recv_exactly(client, 6) == b"during"  # the connection lived through it
        assert emu.counters()["outages"] == 1


def test_an_outage_can_reset_connections(peer):
    echo = peer(echo=True)
    link = profile("custom", delay_ms=5, reset_on_outage=True)
    with LinkEmulator(link, "127.0.0.1:0", echo.address) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        client.sendall(b"ok")
        assert recv_exactly(client, 2) == b"ok"
        emu.outage(1.0)
        client.settimeout(10)
        with contextlib.suppress(ConnectionResetError):
            assert client.recv(10) == b""  # closed by the emulator
        wait_until(lambda: emu.counters()["connections"] == 0, timeout=10, what="connection dropped")


def test_two_connections_share_one_bottleneck(peer):
    sink = peer()
    link = profile("custom", rate_kbps=4000, delay_ms=5, buffer_kb=64)  # 500 kB/s for both together
    size = 600_000
    with LinkEmulator(link, "127.0.0.1:0", sink.address) as emu:
        clients = [socket.create_connection(("127.0.0.1", emu.port)) for _ in range(2)]
        try:
            t0 = time.monotonic()
            senders = [threading.Thread(target=c.sendall, args=(b"y" * size,)) for c in clients]
            for s in senders:
                s.start()
            wait_until(lambda: sum(sink.received) >= size, timeout=30, what="half the bytes through")
            shares = list(sink.received)
            wait_until(lambda: sum(sink.received) == 2 * size, timeout=30, what="all bytes through")
            elapsed = time.monotonic() - t0
            for s in senders:
                s.join(10)
        finally:
            for c in clients:
                c.close()
    assert elapsed >= 0.9 * 2 * size / 500_000  # together no faster than one link
    assert len(shares) == 2 and min(shares) > 0.2 * sum(shares)  # and both got a share meanwhile


def test_a_full_buffer_pushes_back_on_the_sender(peer):
    sink = peer()
    link = profile("custom", rate_kbps=1000, delay_ms=5, buffer_kb=32)
    with LinkEmulator(link, "127.0.0.1:0", sink.address) as emu, socket.socket() as client:
        client.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 32 * 1024)
        client.connect(("127.0.0.1", emu.port))
        emu.outage(5)
        client.setblocking(False)
        accepted = 0
        deadline = time.monotonic() + 3
        while time.monotonic() < deadline:
            try:
                accepted += client.send(b"z" * 65536)
            except BlockingIOError:
                time.sleep(0.05)  # the sender is pushed back; try again: still full?
        counters = emu.counters()
        assert counters["up"]["queue_bytes"] == 32_000  # the buffer is full, and holds
        assert counters["up"]["bytes_passed"] == 0
        # Without backpressure the sender would have written ~all it tried in 3 s; with it, the
        # buffer plus a few socket buffers.
        assert 32_000 <= accepted < 2_000_000


class UdpPeer:
    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 * 1024 * 1024)
        self.sock.bind(("127.0.0.1", 0))
        self.address = self.sock.getsockname()
        self.received: list[bytes] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        with contextlib.suppress(OSError):
            while True:
                data, addr = self.sock.recvfrom(65536)
                self.received.append(data)
                self.sock.sendto(b"re:" + data, addr)

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def udp_peer():
    p = UdpPeer()
    yield p
    p.close()


def test_udp_loss_rate_is_about_the_profiles(udp_peer):
    link = profile("custom", rate_kbps=100_000, delay_ms=2, buffer_kb=10_000, loss=0.1)
    n = 2000
    with LinkEmulator(link, udp_listen="127.0.0.1:0", udp_target=udp_peer.address, seed=42) as emu, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as client:
        for i in range(n):
            client.sendto(i.to_bytes(4, "big"), ("127.0.0.1", emu.udp_port))
            if i % 20 == 19:
                time.sleep(0.01)  # well under the cap: losses are the profile's, not the buffer's
        wait_until(lambda: emu.counters()["up"]["bytes_in"] == 4 * n, timeout=20, what="every datagram seen")
        counters = wait_until(lambda: (c := emu.counters())["up"]["in_flight"] == 0 and c, timeout=10,
                              what="the link drained")
    dropped = counters["up"]["packets_dropped"]
    assert 0.07 * n <= dropped <= 0.13 * n
    wait_until(lambda: len(udp_peer.received) == n - dropped, timeout=10, what="the rest delivered")


def test_udp_replies_come_back_and_an_outage_drops_everything(udp_peer):
    link = profile("custom", rate_kbps=10_000, delay_ms=5)
    with LinkEmulator(link, udp_listen="127.0.0.1:0", udp_target=udp_peer.address) as emu, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as client:
        target = ("127.0.0.1", emu.udp_port)
        client.settimeout(10)
        client.sendto(b"hello", target)
        assert client.recvfrom(100)[0] == b"re:hello"  # both ways, through the client's own flow
        emu.outage(2.0)
        for i in range(50):
            client.sendto(b"lost%d" % i, target)
        wait_until(lambda: emu.counters()["up"]["packets_dropped"] == 50, timeout=10, what="50 dropped")
        assert len(udp_peer.received) == 1
        wait_until(lambda: emu.counters()["outages"] == 1 and not emu.schedule.down(time.monotonic()),
                   timeout=10, what="the outage over")
        client.sendto(b"after", target)
        assert client.recvfrom(100)[0] == b"re:after"


def test_live_profile_change(peer):
    echo = peer(echo=True)
    with LinkEmulator("wifi-good", "127.0.0.1:0", echo.address, seed=3) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        emu.set_profile(profile("custom", delay_ms=150))
        t0 = time.monotonic()
        client.sendall(b"slow")
        assert recv_exactly(client, 4) == b"slow"
        assert time.monotonic() - t0 >= 0.3
        assert emu.profile.delay_ms == 150


def test_the_flask_command_relays_and_stops(peer, tmp_path):
    echo = peer(echo=True)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env["PYTHONPATH"] = str(ROOT)
    env["ROVER_WEB_SECRET_KEY"] = "test"
    proc = subprocess.Popen([sys.executable, "-m", "flask", "--app", "rover_web", "link-emulator",
                             "--profile", "custom", "--delay-ms", "20", "--seed", "1",
                             "--listen", f"127.0.0.1:{port}", "--target", f"127.0.0.1:{echo.address[1]}"],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        assert "link-emulator: custom" in line and f"127.0.0.1:{port}" in line
        with socket.create_connection(("127.0.0.1", port), timeout=10) as client:
            t0 = time.monotonic()
            client.sendall(b"through the command")
            assert recv_exactly(client, 19) == b"through the command"
            assert time.monotonic() - t0 >= 0.04
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(15) == 0
        assert "stopped" in proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
        proc.stdout.close()
        proc.stderr.close()


def test_the_flask_command_refuses_a_missing_target():
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env["PYTHONPATH"] = str(ROOT)
    done = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "link-emulator",
                           "--listen", "127.0.0.1:0"], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "--target" in done.stderr


def test_a_stall_holds_every_byte_for_its_length(peer):
    echo = peer(echo=True)
    with LinkEmulator(profile("custom", delay_ms=5), "127.0.0.1:0", echo.address) as emu, \
            socket.create_connection(("127.0.0.1", emu.port)) as client:
        client.sendall(b"warm")
        assert recv_exactly(client, 4) == b"warm"
        emu.stall(800)
        t0 = time.monotonic()
        client.sendall(b"held")
        client.settimeout(15)
        assert recv_exactly(client, 4) == b"held"
        assert time.monotonic() - t0 >= 0.7  # the stall began before the send: at least the rest of it
        assert emu.counters()["stalls"] == 1
