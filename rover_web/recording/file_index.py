"""A recording's chunk map, for reading parts of it: which chunks, when, which channels, how many.

The replay view asks questions such as "the frame on /camera at 14:32:05" or "/odom's x over the
run"; reading the whole file for each would cost seconds per move of the slider on a long
recording. An index lists the file's chunks with their time span and channels, so a question
decompresses only the chunks it needs (mcap's Chunk records and `breakup_chunk`, as its
SeekingReader reads them):

- a finished file with a summary: read from the summary (chunk indexes, channels, schemas,
  statistics) at the end of the file, without reading its data;
- a file cut by a crash (no summary), or written without one: one pass over its records, each
  chunk decompressed once to learn its channels and counts; a damaged chunk ends the pass like a
  cut. `walk(path, strict=True)` instead refuses anything damaged, cut or not MCAP (uploads).

Indexes of the last few files are kept (a file never changes once finished: keyed by path, size
and modification time). Every query opens its own file handle: an index is never changed after
it is built, so request threads share it freely.
"""

from __future__ import annotations

import math
import struct
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Message, Schema
from mcap_ros2.decoder import DecoderFactory

from .reading import MAGIC, NotARecording, cut_or_damaged, read_messages

CACHED_FILES = 8
_RECORD_HEAD = struct.Struct("<BQ")  # opcode, content length


class Refused(NotARecording):
    """A file refused by walk(strict=True) (and one that is not MCAP at all, by any walk): `code`
    is not_mcap, truncated or corrupt."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class ChunkRef:
    offset: int  # of the chunk record's opcode
    start_ns: int
    end_ns: int
    channels: frozenset[int]


@dataclass
class FileIndex:
    path: Path
    complete: bool  # the footer was there: the file was finished properly
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    chunks: list[ChunkRef] = field(default_factory=list)
    counts: dict[int, int] = field(default_factory=dict)  # messages per channel id
    start_ns: int | None = None
    end_ns: int | None = None
    loose: bool = False  # messages outside chunks (an unchunked file): read by a scan of the whole file
    _decoders: dict[int, Callable | None] = field(default_factory=dict, repr=False)
    _factory: DecoderFactory = field(default_factory=DecoderFactory, repr=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    # --- what is in it ---

    def channel_ids(self, topics: Iterable[str]) -> set[int]:
        wanted = set(topics)
        return {cid for cid, channel in self.channels.items() if channel.topic in wanted}

    def topics(self) -> dict[str, dict]:
        """topic -> {"type", "count", "decodable"} for every channel with messages."""
        out: dict[str, dict] = {}
        for cid, channel in self.channels.items():
            schema = self.schemas.get(channel.schema_id)
            entry = out.setdefault(channel.topic, {"type": schema.name if schema else "", "count": 0,
                                                   "decodable": self.decoder(cid) is not None})
            entry["count"] += self.counts.get(cid, 0)
        return {topic: entry for topic, entry in sorted(out.items()) if entry["count"]}

    def type_of(self, topic: str) -> str | None:
        for channel in self.channels.values():
            if channel.topic == topic:
                schema = self.schemas.get(channel.schema_id)
                return schema.name if schema else ""
        return None

    def count(self, topics: Iterable[str]) -> int:
        return sum(self.counts.get(cid, 0) for cid in self.channel_ids(topics))

    def decoder(self, channel_id: int) -> Callable[[bytes], object] | None:
        """mcap-ros2-support's decoder for the channel (ros2msg schema, CDR), or None."""
        with self._lock:
            if channel_id not in self._decoders:
                channel = self.channels.get(channel_id)
                decode = None
                if channel is not None:
                    try:
                        decode = self._factory.decoder_for(channel.message_encoding,
                                                           self.schemas.get(channel.schema_id))
                    except Exception:  # noqa: BLE001 - a schema it cannot parse: not shown, not a 500
                        decode = None
                self._decoders[channel_id] = decode
            return self._decoders[channel_id]

    def decode(self, message: Message):
        """The decoded message, or None when its channel cannot be decoded or its bytes are damaged."""
        decode = self.decoder(message.channel_id)
        if decode is None:
            return None
        try:
            return decode(message.data)
        except Exception:  # noqa: BLE001 - damaged bytes in a recording: that message is skipped
            return None

    # --- reading ---

    def messages(self, topics: Iterable[str], start_ns: int | None = None,
                 end_ns: int | None = None) -> Iterator[tuple[Channel, Message]]:
        """The messages of `topics` with start_ns <= log time <= end_ns, chunk by chunk in the
        order of their start (roughly in time: callers that need strict order sort)."""
        ids = self.channel_ids(topics)
        if not ids:
            return
        if self.loose:
            for _schema, channel, message in read_messages(self.path):
                if channel.id in ids and _within(message.log_time, start_ns, end_ns):
                    yield channel, message
            return
        chunks = [c for c in self.chunks if c.channels & ids and _overlaps(c, start_ns, end_ns)]
        with open(self.path, "rb") as f:
            for chunk in sorted(chunks, key=lambda c: (c.start_ns, c.offset)):
                for record in self._read_chunk(f, chunk):
                    if isinstance(record, Message) and record.channel_id in ids \
                            and _within(record.log_time, start_ns, end_ns):
                        yield self.channels[record.channel_id], record

    def latest(self, topic: str, t_ns: int) -> tuple[Channel, Message] | None:
        """The last message on `topic` logged at or before t_ns, reading as few chunks as it can."""
        ids = self.channel_ids([topic])
        if not ids:
            return None
        if self.loose:
            best = None
            for channel, message in self.messages([topic], None, t_ns):
                if best is None or message.log_time >= best[1].log_time:
                    best = (channel, message)
            return best
        best: Message | None = None
        candidates = sorted((c for c in self.chunks if c.channels & ids and c.start_ns <= t_ns),
                            key=lambda c: c.end_ns, reverse=True)
        with open(self.path, "rb") as f:
            for chunk in candidates:
                if best is not None and best.log_time >= chunk.end_ns:
                    break  # every chunk left ends before what was found
                for record in self._read_chunk(f, chunk):
                    if isinstance(record, Message) and record.channel_id in ids and record.log_time <= t_ns \
                            and (best is None or record.log_time >= best.log_time):
                        best = record
        return None if best is None else (self.channels[best.channel_id], best)

    @staticmethod
    def _read_chunk(f, chunk: ChunkRef) -> list:
        from mcap.stream_reader import breakup_chunk  # with lz4 and zstandard: see reading.py

        f.seek(chunk.offset + _RECORD_HEAD.size)
        try:
            return breakup_chunk(Chunk.read(ReadDataStream(f)), validate_crc=True)
        except cut_or_damaged():
            return []  # the chunk the index pass read is damaged now: nothing from it


def _within(t: int, start_ns: int | None, end_ns: int | None) -> bool:
    return (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns)


def _overlaps(chunk: ChunkRef, start_ns: int | None, end_ns: int | None) -> bool:
    return (start_ns is None or chunk.end_ns >= start_ns) and (end_ns is None or chunk.start_ns <= end_ns)


# --- building ---


def from_summary(path: Path) -> FileIndex | None:
    """The index of a finished file from its summary; None when it has none to use."""
    try:
        with open(path, "rb") as f:
            if f.read(len(MAGIC)) != MAGIC or not _ends_with_magic(f):
                return None
            f.seek(0)
            from mcap.reader import SeekingReader
            summary = SeekingReader(f).get_summary()
    except (OSError, *cut_or_damaged()):
        return None
    if summary is None or not summary.chunk_indexes or summary.statistics is None \
            or not all(ci.message_index_offsets for ci in summary.chunk_indexes):
        return None  # nothing to tell which chunk holds which channel: the pass over the file will
    index = FileIndex(path, complete=True, schemas=dict(summary.schemas), channels=dict(summary.channels),
                      counts=dict(summary.statistics.channel_message_counts))
    for ci in summary.chunk_indexes:
        index.chunks.append(ChunkRef(ci.chunk_start_offset, ci.message_start_time, ci.message_end_time,
                                     frozenset(ci.message_index_offsets)))
    if summary.statistics.message_count:
        index.start_ns = summary.statistics.message_start_time
        index.end_ns = summary.statistics.message_end_time
    return index


def walk(path: Path, strict: bool = False) -> FileIndex:
    """The index from one pass over the file's records. Lenient (default): stops quietly where the
    file is cut or damaged (NotARecording if nothing readable came before). Strict: Refused for a
    file that is not MCAP, is cut short, or has any damaged record or chunk (CRC, compression)."""
    try:
        size = path.stat().st_size
        with open(path, "rb") as f:
            if f.read(len(MAGIC)) != MAGIC:
                raise Refused("not_mcap", "this is not an MCAP file (it does not start with the MCAP magic bytes)")
            ends_well = _ends_with_magic(f)
            if strict and not ends_well:
                raise Refused("truncated", "the file is cut short: it does not end with MCAP's closing magic bytes "
                                           "(a copy or download that stopped early, or a recording cut by a crash; "
                                           "`mcap recover` rewrites such a file whole)")
            f.seek(len(MAGIC))
            index = FileIndex(path, complete=False)
            try:
                _walk_records(f, size, index)
            except cut_or_damaged() as exc:
                if strict:
                    raise Refused("corrupt", f"the file is damaged at byte {f.tell()} "
                                             f"({type(exc).__name__}: {str(exc)[:120]})") from None
                if not index.channels:
                    raise NotARecording(f"{path} is damaged before its first message ({type(exc).__name__})") \
                        from None
            if strict and not index.complete:
                raise Refused("truncated", "the file is cut short: its records stop before the footer")
            return index
    except OSError as exc:
        raise NotARecording(f"cannot read {path}: {exc.strerror or exc}") from None


def _ends_with_magic(f) -> bool:
    f.seek(0, 2)
    if f.tell() < 2 * len(MAGIC):
        return False
    f.seek(-len(MAGIC), 2)
    return f.read(len(MAGIC)) == MAGIC


def _walk_records(f, size: int, index: FileIndex) -> None:
    from mcap.stream_reader import breakup_chunk

    while True:
        head = f.read(_RECORD_HEAD.size)
        if len(head) < _RECORD_HEAD.size:
            return  # cut between records
        opcode, length = _RECORD_HEAD.unpack(head)
        at = f.tell()
        if at + length > size:
            return  # cut inside this record
        stream = ReadDataStream(f)
        if opcode == Opcode.CHUNK:
            records = breakup_chunk(Chunk.read(stream), validate_crc=True)
            channels: set[int] = set()
            for record in records:
                if isinstance(record, Message):
                    channels.add(record.channel_id)
                    _count(index, record)
                else:
                    _describe(index, record)
            if channels:
                times = [r.log_time for r in records if isinstance(r, Message)]
                index.chunks.append(ChunkRef(at - _RECORD_HEAD.size, min(times), max(times), frozenset(channels)))
        elif opcode == Opcode.SCHEMA:
            _describe(index, Schema.read(stream))
        elif opcode == Opcode.CHANNEL:
            _describe(index, Channel.read(stream))
        elif opcode == Opcode.MESSAGE:
            index.loose = True
            _count(index, Message.read(stream, length))
        elif opcode == Opcode.FOOTER:
            index.complete = True
            return
        f.seek(at + length)


def _describe(index: FileIndex, record) -> None:
    if isinstance(record, Schema):
        index.schemas.setdefault(record.id, record)
    elif isinstance(record, Channel):
        index.channels.setdefault(record.id, record)


def _count(index: FileIndex, message: Message) -> None:
    index.counts[message.channel_id] = index.counts.get(message.channel_id, 0) + 1
    t = message.log_time
    index.start_ns = t if index.start_ns is None else min(index.start_ns, t)
    index.end_ns = t if index.end_ns is None else max(index.end_ns, t)


# --- the cache ---

_cache: OrderedDict[tuple, FileIndex] = OrderedDict()
_cache_lock = threading.Lock()
_building: dict[tuple, threading.Lock] = {}


def _key(path: Path) -> tuple:
    stat = path.stat()
    return str(path), stat.st_size, stat.st_mtime_ns


def index_of(path: Path) -> FileIndex:
    """The file's index, built once (from its summary, else by a pass over it); NotARecording for a
    file that is not MCAP or has nothing readable."""
    try:
        key = _key(path)
    except OSError as exc:
        raise NotARecording(f"cannot read {path}: {exc.strerror or exc}") from None
    with _cache_lock:
        if key in _cache:
            _cache.move_to_end(key)
            return _cache[key]
        building = _building.setdefault(key, threading.Lock())
    with building:  # two requests for a new file: one builds, the other waits for it
        with _cache_lock:
            if key in _cache:
                return _cache[key]
        try:
            index = from_summary(path) or walk(path)
            remember(path, index, key)
        finally:
            with _cache_lock:
                _building.pop(key, None)
        return index


def remember(path: Path, index: FileIndex, key: tuple | None = None) -> None:
    """Keep an index built elsewhere (an upload's strict pass) for its file."""
    key = key or _key(path)
    index.path = path
    with _cache_lock:
        _cache[key] = index
        _cache.move_to_end(key)
        while len(_cache) > CACHED_FILES:
            _cache.popitem(last=False)


def forget(path: Path) -> None:
    with _cache_lock:
        for key in [k for k in _cache if k[0] == str(path)]:
            del _cache[key]


def stride_for(count: int, most: int) -> int:
    """Keep every stride-th of `count` items so that at most `most` are kept."""
    return max(1, math.ceil(count / most)) if most > 0 else 1


__all__ = ["FileIndex", "ChunkRef", "Refused", "McapError", "index_of", "walk", "from_summary", "remember",
           "forget", "stride_for"]
