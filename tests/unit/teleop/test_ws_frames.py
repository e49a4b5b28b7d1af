"""rover_web.ws_frames against wsproto (which simple_websocket and flask-sock use) as the oracle:
for any mix of client frames, split anywhere, both must see the same messages and controls, and
for a broken stream both must fail with the same close code."""

import os
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from wsproto import ConnectionType, WSConnection
from wsproto.events import AcceptConnection, BytesMessage, CloseConnection, Message, Ping, Pong, Request, TextMessage

from rover_web.teleop.ws_frames import (
    CLOSE_INVALID_PAYLOAD,
    CLOSE_MESSAGE_TOO_BIG,
    CLOSE_NO_STATUS,
    CLOSE_PROTOCOL_ERROR,
    FrameParser,
    ProtocolError,
    close_frame,
    frame,
    text_frame,
)
from tests.support.ws_wire import masked

BIG = 1 << 30


def connected_pair() -> tuple[WSConnection, WSConnection]:
    client, server = WSConnection(ConnectionType.CLIENT), WSConnection(ConnectionType.SERVER)
    server.receive_data(client.send(Request(host="rover", target="/ws/teleop")))
    for event in server.events():
        assert isinstance(event, Request)
        client.receive_data(server.send(AcceptConnection()))
    assert all(isinstance(e, AcceptConnection) for e in client.events())
    return client, server


def wsproto_events(server: WSConnection, chunks: list[bytes]) -> list:
    """What wsproto's server side makes of the stream: whole messages, controls, a failure."""
    out, parts = [], []
    for chunk in chunks:
        server.receive_data(chunk)
        for event in server.events():
            if isinstance(event, (TextMessage, BytesMessage)):
                parts.append(event.data)
                if event.message_finished:
                    joined = "".join(parts) if isinstance(event, TextMessage) else b"".join(parts)
                    out.append(("text" if isinstance(event, TextMessage) else "binary", joined))
                    parts = []
            elif isinstance(event, Ping):
                out.append(("ping", bytes(event.payload)))
            elif isinstance(event, Pong):
                out.append(("pong", bytes(event.payload)))
            elif isinstance(event, CloseConnection):
                out.append(("close", (int(event.code), event.reason)))
                return out
    return out


def our_events(chunks: list[bytes], max_bytes: int = BIG) -> list:
    parser, out = FrameParser(max_bytes), []
    for chunk in chunks:
        try:
            events = parser.feed(chunk)
        except ProtocolError as exc:
            return out + exc.events + [("close", (exc.close_code, exc.message))]
        for event in events:
            out.append(event)
            if event[0] == "close":
                return out
    return out


def split(data: bytes, cuts: list[int]) -> list[bytes]:
    points = sorted({c % (len(data) + 1) for c in cuts})
    return [data[a:b] for a, b in zip([0] + points, points + [len(data)], strict=True)]


def same_outcome(ours: list, theirs: list) -> None:
    """Equal events; a failure must carry the same code (the messages are each side's own words)."""
    strip = [(kind, body[0]) if kind == "close" else (kind, body) for kind, body in ours]
    assert strip == [(kind, body[0]) if kind == "close" else (kind, body) for kind, body in theirs]
    for (kind, body), (_, their_body) in zip(ours, theirs, strict=True):
        if kind == "close" and body[0] not in (CLOSE_PROTOCOL_ERROR, CLOSE_INVALID_PAYLOAD):
            assert body == their_body  # a peer's own close: the reason too


# --- valid streams ---

texts = st.text(max_size=300)
blobs = st.binary(max_size=300)
control_payloads = st.binary(max_size=125)
peer_codes = st.sampled_from([1000, 1001, 1002, 1003, 1007, 1008, 1009, 1010, 1011, 1012, 1013, 3000, 4999])
close_reasons = st.text(max_size=20).filter(lambda r: len(r.encode()) <= 123)

actions = st.one_of(
    st.tuples(st.just("text"), texts, st.integers(1, 4)),
    st.tuples(st.just("binary"), blobs, st.integers(1, 4)),
    st.tuples(st.just("ping"), control_payloads),
    st.tuples(st.just("pong"), control_payloads),
)


def send_message(client: WSConnection, data, pieces: int, interleave: bytes) -> bytes:
    """One message in `pieces` frames, with a ping between the first two when fragmented."""
    size = max(1, len(data) // pieces)
    chunks = [data[i:i + size] for i in range(0, len(data), size)] or [data]
    out = b""
    for i, chunk in enumerate(chunks):
        out += client.send(Message(data=chunk, message_finished=i == len(chunks) - 1))
        if i == 0 and len(chunks) > 1:
            out += client.send(Ping(payload=interleave))
    return out


@settings(max_examples=300, deadline=None)
@given(st.lists(actions, max_size=12), st.one_of(st.none(), st.tuples(peer_codes, close_reasons)),
       st.lists(st.integers(0, 1 << 16), max_size=8))
def test_any_valid_stream_split_anywhere_reads_as_wsproto_reads_it(script, close, cuts):
    client, server = connected_pair()
    stream = b""
    for action in script:
        if action[0] in ("text", "binary"):
            stream += send_message(client, action[1], action[2], b"between")
        elif action[0] == "ping":
            stream += client.send(Ping(payload=action[1]))
        else:
            stream += client.send(Pong(payload=action[1]))
    if close is not None:
        stream += client.send(CloseConnection(code=close[0], reason=close[1]))
    chunks = split(stream, cuts)
    ours, theirs = our_events(chunks), wsproto_events(server, chunks)
    same_outcome(ours, theirs)
    assert (len([e for e in ours if e[0] in ("text", "binary")])
            == len([a for a in script if a[0] in ("text", "binary")]))


# --- broken streams ---

headers = st.integers(0, 255)
short_payloads = st.binary(max_size=140)


@settings(max_examples=500, deadline=None)
@given(st.lists(st.tuples(headers, short_payloads, st.booleans()), min_size=1, max_size=5),
       st.lists(st.integers(0, 1000), max_size=4))
def test_any_hand_built_frames_fail_or_pass_as_in_wsproto(frames_, cuts):
    """Random first bytes (FIN, RSV, opcode), payloads and mask bits: frames that are fine, and
    every way of breaking the rules that fits in a header."""
    stream = b"".join(masked(first, payload, mask_bit=mask_bit) for first, payload, mask_bit in frames_)
    chunks = split(stream, cuts)
    same_outcome(our_events(chunks), wsproto_events(connected_pair()[1], chunks))


@pytest.mark.parametrize("stream, code", [
    (masked(0x81, b"hi", mask_bit=False), CLOSE_PROTOCOL_ERROR),            # unmasked
    (masked(0xC1, b"hi"), CLOSE_PROTOCOL_ERROR),                            # RSV1: no deflate was agreed
    (masked(0x83, b"hi"), CLOSE_PROTOCOL_ERROR),                            # reserved opcode
    (masked(0x09, b"hi"), CLOSE_PROTOCOL_ERROR),                            # fragmented ping
    (masked(0x89, b"x" * 126), CLOSE_PROTOCOL_ERROR),                       # control frame over 125 bytes
    (masked(0x80, b"hi"), CLOSE_PROTOCOL_ERROR),                            # continuation of nothing
    (masked(0x01, b"a") + masked(0x81, b"b"), CLOSE_PROTOCOL_ERROR),        # new message inside a message
    (masked(0x81, b"hi", length=bytes([126, 0, 2])), CLOSE_PROTOCOL_ERROR),  # length not minimally encoded
    (masked(0x81, b"hi", length=bytes([127]) + struct.pack("!Q", 2)), CLOSE_PROTOCOL_ERROR),
    (masked(0x81, b"\xff\xfe"), CLOSE_INVALID_PAYLOAD),                     # not UTF-8
    (masked(0x01, b"\xe2\x82") + masked(0x80, b"\xac!"), None),             # UTF-8 split across frames: fine
    (masked(0x88, b"\x03"), CLOSE_PROTOCOL_ERROR),                          # one-byte close payload
    (masked(0x88, struct.pack("!H", 1005)), CLOSE_PROTOCOL_ERROR),          # local-only close code
    (masked(0x88, struct.pack("!H", 2000)), CLOSE_PROTOCOL_ERROR),          # reserved close code
    (masked(0x88, struct.pack("!H", 1000) + b"\xff"), CLOSE_INVALID_PAYLOAD),  # close reason not UTF-8
])
def test_each_rule_fails_with_its_code_as_in_wsproto(stream, code):
    ours, theirs = our_events([stream]), wsproto_events(connected_pair()[1], [stream])
    same_outcome(ours, theirs)
    if code is None:
        assert ours == [("text", "€!")]
    else:
        assert ours[-1][0] == "close" and ours[-1][1][0] == code


def test_a_close_without_a_code_reads_as_1005_and_ends_the_stream():
    assert our_events([masked(0x88, b"") + masked(0x81, b"late")]) == [("close", (CLOSE_NO_STATUS, ""))]


def test_an_oversized_message_fails_on_its_header_before_its_payload_arrives():
    parser = FrameParser(max_message_bytes=4096)
    whole = masked(0x81, b"x" * 5000)
    with pytest.raises(ProtocolError) as exc:
        parser.feed(whole[:8])  # the header says 5000 bytes; none of the payload has come
    assert exc.value.close_code == CLOSE_MESSAGE_TOO_BIG


def test_fragments_count_together_against_the_limit():
    parser = FrameParser(max_message_bytes=100)
    parser.feed(masked(0x01, b"x" * 60))
    with pytest.raises(ProtocolError) as exc:
        parser.feed(masked(0x80, b"x" * 60)[:6])
    assert exc.value.close_code == CLOSE_MESSAGE_TOO_BIG
    assert FrameParser(max_message_bytes=100).feed(masked(0x81, b"x" * 100)) == [("text", "x" * 100)]


@pytest.mark.parametrize("payload", [b"", b"x"])
def test_a_message_in_too_many_fragments_fails_1009_even_when_they_are_empty(payload):
    """Empty fragments add nothing to a message's bytes: without a count, one socket could send
    them for ever and the server would keep every one."""
    parser = FrameParser(max_message_bytes=4096, max_fragments=64)
    parser.feed(masked(0x01, payload) + masked(0x00, payload) * 63)  # 64 frames, none final: allowed so far
    with pytest.raises(ProtocolError) as exc:
        parser.feed(masked(0x00, payload))
    assert exc.value.close_code == CLOSE_MESSAGE_TOO_BIG and "64 frames" in str(exc.value)
    whole = FrameParser(max_message_bytes=4096, max_fragments=64)
    assert whole.feed(masked(0x01, b"a") + masked(0x00, b"") * 62 + masked(0x80, b"b")) == [("text", "ab")]


def test_frames_arriving_a_byte_at_a_time_come_out_whole_and_in_order():
    stream = masked(0x81, b'{"linear": 0.5}') + masked(0x89, b"p") + masked(0x82, os.urandom(300))
    parser, out = FrameParser(4096), []
    for i in range(len(stream)):
        out += parser.feed(stream[i:i + 1])
    assert [kind for kind, _ in out] == ["text", "ping", "binary"]
    assert out[0] == ("text", '{"linear": 0.5}')


# --- what the server sends ---

@pytest.mark.parametrize("size", [0, 125, 126, 65535, 65536])
def test_server_frames_read_back_in_wsproto_at_every_length_encoding(size):
    client, _ = connected_pair()
    client.receive_data(text_frame("é" * (size // 2) + "x" * (size % 2)) + frame(0x2, b"\x00" * size))
    events = list(client.events())
    assert events[0].data == "é" * (size // 2) + "x" * (size % 2) and events[0].message_finished
    assert bytes(events[1].data) == b"\x00" * size


def test_close_frames_carry_the_code_and_a_reason_cut_to_fit_on_a_character_boundary():
    client, _ = connected_pair()
    client.receive_data(close_frame(1009, "é" * 100))
    (event,) = list(client.events())
    assert event.code == 1009 and event.reason == "é" * 61  # 122 of the 123 bytes: no half character
    assert close_frame(CLOSE_NO_STATUS) == b"\x88\x00"
