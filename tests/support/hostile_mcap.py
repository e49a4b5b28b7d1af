"""The hostile MCAP files of the third security review (issue 40), made by hand from raw records, so the
tests and bench/hostile.py refuse the same bytes.

Every file is otherwise well formed (magic, header, a std_msgs String channel, footer), so what
refuses it is the bound it is built to break, not a parse error. `held` sizes default to the
review's; tests pass smaller ones (still over the server's caps) to stay cheap.

- zstd_bomb: one zstd chunk that declares and holds `held` bytes (2 GiB: a 64 KB file)
- lz4_bomb: one lz4 chunk that declares 1 KiB and holds `held` bytes (1 GiB: 4.4 MB)
- attachment_bomb: a small honest chunk, then an Attachment record whose bytes are a zstd bomb
  chunk's, and a summary whose chunk index points at the attachment
- amplification: one 8 MB message of an array of empty messages (a few hundred bytes), named
  nav_msgs/msg/Odometry so the timeline decodes it; `copies` of it in as many chunks
- many_fields: a schema of 200,000 fields (the parser's duplicate check is quadratic)
- many_chunks: 100 zstd chunks of 32 MiB each (114 KB)
"""

from __future__ import annotations

import io
import struct
from pathlib import Path

from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, ChunkIndex, DataEnd, Footer, Header, Message, Schema, Statistics

MAGIC = b"\x89MCAP0\r\n"
T0_NS = 1_764_000_000 * 1_000_000_000
GIB = 1 << 30
MIB = 1 << 20
STRING_SCHEMA = Schema(id=1, name="std_msgs/msg/String", encoding="ros2msg", data=b"string data\n")
STRING_CHANNEL = Channel(id=1, topic="/chatter", message_encoding="cdr", schema_id=1, metadata={})
_BLOCK = bytes(4 * MIB)
PAD_OPCODE = 0x80  # a record type readers skip (MCAP keeps 0x80-0xFF for users)


def _record(record) -> bytes:
    builder = RecordBuilder()
    record.write(builder)
    return builder.end()


def string_cdr(text: str) -> bytes:
    raw = text.encode() + b"\0"
    return b"\x00\x01\x00\x00" + struct.pack("<I", len(raw)) + raw


def _message(channel_id: int = 1, t_ns: int = T0_NS, data: bytes | None = None, sequence: int = 0) -> bytes:
    return _record(Message(channel_id=channel_id, sequence=sequence, log_time=t_ns, publish_time=t_ns,
                           data=string_cdr("hello") if data is None else data))


def _padding_head(length: int) -> bytes:
    return struct.pack("<BQ", PAD_OPCODE, length)


def _zstd_of(head: bytes, zeros: int) -> bytes:
    """A zstd frame declaring and holding `head` followed by `zeros` zero bytes, made a block at a time."""
    import zstandard

    out = io.BytesIO()
    with zstandard.ZstdCompressor(level=1).stream_writer(out, size=len(head) + zeros, closefd=False) as writer:
        writer.write(head)
        left = zeros
        while left:
            step = min(left, len(_BLOCK))
            writer.write(_BLOCK[:step])
            left -= step
    return out.getvalue()


def _lz4_of(head: bytes, zeros: int) -> bytes:
    import lz4.frame

    compressor = lz4.frame.LZ4FrameCompressor()
    parts = [compressor.begin(), compressor.compress(head)]
    left = zeros
    while left:
        step = min(left, len(_BLOCK))
        parts.append(compressor.compress(_BLOCK[:step]))
        left -= step
    parts.append(compressor.flush())
    return b"".join(parts)


def _held(held: int) -> tuple[bytes, int]:
    """The start of a chunk's content that holds `held` bytes: one honest message, then a padding
    record (skipped by readers) whose zeros fill the rest."""
    message = _message()
    head = message + _padding_head(held - len(message) - 9)
    return head, held - len(head)


def bomb_chunk(held: int, compression: str = "zstd", declared: int | None = None) -> Chunk:
    head, zeros = _held(held)
    data = _zstd_of(head, zeros) if compression == "zstd" else _lz4_of(head, zeros)
    return Chunk(compression=compression, data=data, message_start_time=T0_NS, message_end_time=T0_NS,
                 uncompressed_crc=0, uncompressed_size=held if declared is None else declared)


def honest_chunk(messages: list[bytes], start_ns: int = T0_NS, end_ns: int = T0_NS) -> Chunk:
    content = b"".join(messages)
    return Chunk(compression="", data=content, message_start_time=start_ns, message_end_time=end_ns,
                 uncompressed_crc=0, uncompressed_size=len(content))


def _write(path: Path, data_records: list[bytes], summary: list[bytes] | None = None) -> Path:
    body = MAGIC + _record(Header(profile="ros2", library="hostile_mcap")) + b"".join(data_records)
    body += _record(DataEnd(data_section_crc=0))
    summary_start = len(body) if summary else 0
    body += b"".join(summary or [])
    body += _record(Footer(summary_start=summary_start, summary_offset_start=0, summary_crc=0)) + MAGIC
    path.write_bytes(body)
    return path


def _plain(path: Path, chunks: list[Chunk], schema: Schema = STRING_SCHEMA, channel: Channel = STRING_CHANNEL) -> Path:
    return _write(path, [_record(schema), _record(channel), *(_record(c) for c in chunks)])


def zstd_bomb(path: Path, held: int = 2 * GIB) -> Path:
    return _plain(path, [bomb_chunk(held, "zstd")])


def lz4_bomb(path: Path, held: int = GIB) -> Path:
    return _plain(path, [bomb_chunk(held, "lz4", declared=1024)])


def attachment_bomb(path: Path, held: int = 2 * GIB) -> Path:
    """An honest file whose summary's chunk index points at an Attachment record holding a bomb chunk."""
    head = [_record(STRING_SCHEMA), _record(STRING_CHANNEL)]
    honest = _record(honest_chunk([_message()]))
    bomb = bytearray(_record(bomb_chunk(held, "zstd")))
    bomb[0] = Opcode.ATTACHMENT  # a chunk's content under the opcode of an attachment: a strict walk skips it
    start = len(MAGIC) + len(_record(Header(profile="ros2", library="hostile_mcap"))) + sum(map(len, head))
    bomb_at = start + len(honest)
    summary = [_record(STRING_SCHEMA), _record(STRING_CHANNEL),
               _record(Statistics(message_count=1, schema_count=1, channel_count=1, attachment_count=0,
                                  metadata_count=0, chunk_count=1, message_start_time=T0_NS,
                                  message_end_time=T0_NS, channel_message_counts={1: 1})),
               _record(ChunkIndex(message_start_time=T0_NS, message_end_time=T0_NS, chunk_start_offset=bomb_at,
                                  chunk_length=len(bomb), message_index_offsets={1: bomb_at + len(bomb)},
                                  message_index_length=0, compression="zstd", compressed_size=len(bomb),
                                  uncompressed_size=held))]
    return _write(path, [*head, honest, bytes(bomb)], summary)


def empty_array_message(length: int = 8 * MIB) -> bytes:
    """CDR of `Empty[] items` with `length` elements: each costs one byte (ROS's placeholder member)."""
    return b"\x00\x01\x00\x00" + struct.pack("<I", length) + bytes(length)


AMPLIFYING_SCHEMA = Schema(id=1, name="nav_msgs/msg/Odometry", encoding="ros2msg",
                           data=b"Empty[] items\n" + b"=" * 80 + b"\nMSG: nav_msgs/Empty\n")
AMPLIFYING_CHANNEL = Channel(id=1, topic="/odom", message_encoding="cdr", schema_id=1, metadata={})


def amplification(path: Path, length: int = 8 * MIB, copies: int = 1) -> Path:
    """`copies` chunks of the one message (the same bytes, the same time: the timeline's 5,000)."""
    message = _message(data=empty_array_message(length))
    chunk = Chunk(compression="zstd", data=_zstd_of(message, 0), message_start_time=T0_NS, message_end_time=T0_NS,
                  uncompressed_crc=0, uncompressed_size=len(message))
    return _plain(path, [chunk] * copies, AMPLIFYING_SCHEMA, AMPLIFYING_CHANNEL)


def many_fields(path: Path, fields: int = 200_000) -> Path:
    text = "".join(f"uint8 f{i}\n" for i in range(fields)).encode()
    schema = Schema(id=1, name="std_msgs/msg/String", encoding="ros2msg", data=text)
    content = _record(schema) + _record(STRING_CHANNEL) + _message(data=b"\x00\x01\x00\x00" + bytes(fields))
    chunk = Chunk(compression="zstd", data=_zstd_of(content, 0), message_start_time=T0_NS, message_end_time=T0_NS,
                  uncompressed_crc=0, uncompressed_size=len(content))
    return _write(path, [_record(chunk)])


def many_chunks(path: Path, chunks: int = 100, held: int = 32 * MIB) -> Path:
    one = bomb_chunk(held, "zstd")
    return _plain(path, [one] * chunks)


HOSTILE = {"zstd_bomb": zstd_bomb, "lz4_bomb": lz4_bomb, "attachment_bomb": attachment_bomb,
           "amplification": amplification, "many_fields": many_fields, "many_chunks": many_chunks}
