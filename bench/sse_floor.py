"""The floor for bench/events.py: a plain-socket SSE writer with no ROS and no web framework.

    .venv/bin/python bench/sse_floor.py --port P [--rate 100]

It answers every connection with an SSE response head and then, RATE times a second, writes one
`odom` frame shaped and sized like rover_web's (its `stamp` the CLOCK_MONOTONIC time it was made)
to every client with one non-blocking send each, from one thread; a client whose socket is full
keeps its unsent bytes and skips frames until they are out, as rover_web's streams do. What
rover_web costs above this is what the framework, ROS and our own code add per event and per
viewer. Prints "listening" once it accepts.
"""

from __future__ import annotations

import argparse
import json
import selectors
import socket
import time

HEAD = (b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
        b"Connection: close\r\n\r\n")


def odom_frame(seq: int) -> bytes:
    # The fields of rover_web's `odom` event, so both write about the same bytes.
    data = {"x": float(seq), "y": 0.0, "yaw": 0.0, "linear": 0.0, "angular": 0.0, "frame_id": "odom",
            "stamp": time.monotonic()}
    return f"id: {seq}\nevent: odom\ndata: {json.dumps(data, separators=(',', ':'))}\n\n".encode()


def serve(port: int, rate: float) -> None:
    listener = socket.create_server(("127.0.0.1", port), backlog=1024)
    listener.setblocking(False)
    sel = selectors.DefaultSelector()
    sel.register(listener, selectors.EVENT_READ, None)
    clients: dict[socket.socket, bytes] = {}  # socket -> bytes not yet sent
    pending: set[socket.socket] = set()  # connected, request not yet read
    print("listening", flush=True)
    period, seq = 1.0 / rate, 0
    next_t = time.monotonic()
    while True:
        for key, _ in sel.select(max(0.0, next_t - time.monotonic())):
            sock = key.fileobj
            if sock is listener:
                try:
                    conn, _ = listener.accept()
                except BlockingIOError:
                    continue
                conn.setblocking(False)
                sel.register(conn, selectors.EVENT_READ, None)
                pending.add(conn)
            elif sock in pending:
                try:
                    request = sock.recv(65536)
                except BlockingIOError:
                    continue
                if b"\r\n\r\n" in request:
                    pending.discard(sock)
                    sock.send(HEAD)
                    clients[sock] = b""
            else:  # a client that talks after its request has closed
                sel.unregister(sock)
                clients.pop(sock, None)
                sock.close()
        now = time.monotonic()
        if now < next_t:
            continue
        next_t += period
        seq += 1
        frame = odom_frame(seq)
        for sock, out in clients.items():
            data = out or frame  # a full socket first sends what it holds, then takes new frames
            try:
                sent = sock.send(data, socket.MSG_DONTWAIT | socket.MSG_NOSIGNAL)
            except BlockingIOError:
                sent = 0
            except OSError:
                sent = len(data)
            clients[sock] = data[sent:]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", type=int, required=True)
    parser.add_argument("--rate", type=float, default=100.0)
    args = parser.parse_args()
    try:
        serve(args.port, args.rate)
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
