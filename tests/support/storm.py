"""A reconnect storm, shared by tests/integration/test_reconnect_storm.py and bench/storm.py: waves
of SSE clients and teleop sockets that connect and drop (politely, or with a TCP reset), and an
e-stop probe in a process of its own."""

from __future__ import annotations

import json
import socket
import struct
import subprocess
import sys
import time

import websocket

SSE_CLIENTS, SOCKETS, ROUNDS, STORM_S = 200, 20, 10, 10.0

# Timed from its own process: in the storm's, the storm's threads would hold the interpreter lock
# and the probe would time its own wait for it, not the server.
PROBE = """
import http.client, json, sys, threading, time
port = int(sys.argv[1])
stop = threading.Event()
threading.Thread(target=lambda: (sys.stdin.readline(), stop.set()), daemon=True).start()
conn = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
ms, bad = [], []
print("probing", flush=True)
while not stop.is_set():
    t = time.monotonic()
    conn.request("POST", "/api/estop", body=b'{"engaged": true}', headers={"Content-Type": "application/json"})
    response = conn.getresponse()
    response.read()
    ms.append(1000 * (time.monotonic() - t))
    if response.status != 200:
        bad.append(response.status)
    stop.wait(0.05)
print(json.dumps({"ms": ms, "bad": bad}))
"""


def cut(sock: socket.socket) -> None:
    """Close with a TCP reset, as a dropped Wi-Fi link or a killed browser leaves it."""
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    sock.close()


def open_sse(port: int) -> tuple[socket.socket, int]:
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    sock.sendall(f"GET /api/events?channels=status,odom HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                 f"Accept: text/event-stream\r\n\r\n".encode())
    head = sock.recv(64)
    return sock, int(head.split()[1])


def storm_round(port: int, polite: bool, statuses: list, errors: list) -> None:
    """One wave: every client connects, then all drop at once."""
    opened = []
    for _ in range(SSE_CLIENTS):
        try:
            opened.append(open_sse(port))
        except OSError as exc:
            errors.append(f"sse: {exc}")
    sockets = []
    for _ in range(SOCKETS):
        try:
            sockets.append(websocket.create_connection(f"ws://127.0.0.1:{port}/ws/teleop", timeout=10))
        except websocket.WebSocketBadStatusException as exc:
            statuses.append(exc.status_code)
        except (websocket.WebSocketException, OSError) as exc:
            errors.append(f"ws: {exc}")
    statuses.extend(status for _, status in opened)
    for sock, _ in opened:
        if polite:
            sock.close()
        else:
            cut(sock)
    for ws in sockets:
        if polite:
            ws.close()
        else:
            cut(ws.sock)


def storm(port: int) -> dict:
    """ROUNDS waves, alternately polite and cut, with the e-stop probed every 50 ms throughout."""
    statuses: list[int] = []
    errors: list[str] = []
    prober = subprocess.Popen([sys.executable, "-c", PROBE, str(port)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    assert prober.stdout.readline().strip() == "probing"
    started = time.monotonic()
    try:
        for n in range(ROUNDS):
            storm_round(port, polite=n % 2 == 0, statuses=statuses, errors=errors)
    finally:
        seconds = time.monotonic() - started
        out, _ = prober.communicate("stop\n", timeout=30)
    probed = json.loads(out)
    return {"seconds": seconds, "statuses": statuses, "errors": errors, "estop_ms": probed["ms"],
            "estop_bad": probed["bad"]}


def describe(result: dict) -> str:
    ordered = sorted(result["estop_ms"]) or [float("nan")]
    return (f"{ROUNDS} waves of {SSE_CLIENTS} SSE + {SOCKETS} teleop sockets in {result['seconds']:.1f} s, "
            f"statuses {sorted(set(result['statuses']))}; e-stop p50 {ordered[len(ordered) // 2]:.0f} "
            f"p99 {ordered[int(len(ordered) * 0.99)]:.0f} max {ordered[-1]:.0f} ms over {len(ordered)} requests")
