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

from mcap.exceptions import McapError
from mcap.records import Channel, Footer, Message, Schema
from mcap_ros2.decoder import DecoderFactory

from rover_web.web.api_messages import explain

from . import bounds
from .bounds import Budget, TooCostly
from .reading import MAGIC, NotARecording, Refused, cut_or_damaged, read_messages

CACHED_FILES = 8
_RECORD_HEAD = struct.Struct("<BQ")  # opcode, content length


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
                schema = self.schemas.get(channel.schema_id) if channel is not None else None
                if channel is not None:
                    try:
                        if schema is not None and bounds.amplifies(schema.name, schema.data.decode()):
                            raise ValueError("an array of messages smaller than their Python objects")
                        decode = self._factory.decoder_for(channel.message_encoding, schema)
                    except Exception:  # noqa: BLE001 - a schema it cannot parse: not shown, not a 500
                        decode = None
                self._decoders[channel_id] = decode
            return self._decoders[channel_id]

    def decode(self, message: Message, most: int | None = bounds.DECODE_MAX):
        """The decoded message, or None when its channel cannot be decoded, its bytes are damaged, or
        it is longer than `most` bytes (decoded into Python objects, a message costs tens of times
        its size: only camera frames, decoded one at a time, are let past bounds.DECODE_MAX)."""
        decode = self.decoder(message.channel_id)
        if decode is None or (most is not None and len(message.data) > most):
            return None
        try:
            return decode(message.data)
        except Exception:  # noqa: BLE001 - damaged bytes in a recording: that message is skipped
            return None

    # --- reading ---

    def budget(self) -> Budget:
        """A new allowance for one question of this file (bounds.py)."""
        return Budget(self.path.stat().st_size)

    def messages(self, topics: Iterable[str], start_ns: int | None = None,
                 end_ns: int | None = None, budget: Budget | None = None) -> Iterator[tuple[Channel, Message]]:
        """The messages of `topics` with start_ns <= log time <= end_ns, chunk by chunk in the
        order of their start (roughly in time: callers that need strict order sort); under
        `budget` (one of its own when None): TooCostly over a bound."""
        ids = self.channel_ids(topics)
        if not ids:
            return
        budget = budget or self.budget()
        if self.loose:
            for _schema, channel, message in read_messages(self.path):
                if channel.id in ids and _within(message.log_time, start_ns, end_ns):
                    yield channel, message
            return
        chunks = [c for c in self.chunks if c.channels & ids and _overlaps(c, start_ns, end_ns)]
        with open(self.path, "rb") as f:
            for chunk in sorted(chunks, key=lambda c: (c.start_ns, c.offset)):
                for record in self._read_chunk(f, chunk, ids, budget):
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
        budget = self.budget()
        with open(self.path, "rb") as f:
            for chunk in candidates:
                if best is not None and best.log_time >= chunk.end_ns:
                    break  # every chunk left ends before what was found
                for record in self._read_chunk(f, chunk, ids, budget):
                    if isinstance(record, Message) and record.channel_id in ids and record.log_time <= t_ns \
                            and (best is None or record.log_time >= best.log_time):
                        best = record
        return None if best is None else (self.channels[best.channel_id], best)

    def _read_chunk(self, f, chunk: ChunkRef, ids: set[int], budget: Budget) -> list:
        """The chunk's records, bounded (bounds.py); the offset must hold a Chunk record, whatever
        a summary said (the review's bomb sat in an Attachment its chunk index pointed at)."""
        try:
            content = bounds.read_chunk(f, chunk.offset, budget.file_size, budget)
            return list(bounds.parse_records(content, ids.__contains__, budget))
        except TooCostly:
            raise
        except cut_or_damaged():
            return []  # the chunk the index pass read is damaged now: nothing from it


def _within(t: int, start_ns: int | None, end_ns: int | None) -> bool:
    return (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns)


def _overlaps(chunk: ChunkRef, start_ns: int | None, end_ns: int | None) -> bool:
    return (start_ns is None or chunk.end_ns >= start_ns) and (end_ns is None or chunk.start_ns <= end_ns)


# --- building ---


def from_summary(path: Path) -> FileIndex | None:
    """The index of a finished file from its summary; None when it has none to use. Only for files
    this server wrote (index_of's trust_summary): a summary from elsewhere can point its chunk
    index anywhere, so those files are walked."""
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
    try:
        for schema in summary.schemas.values():
            bounds.check_schema(schema)
    except TooCostly:
        return None  # the walk says which bound, and refuses
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
                raise Refused("not_mcap", explain("this is not an MCAP file (it does not start with the MCAP magic "
                                                  "bytes)"))
            ends_well = _ends_with_magic(f)
            if strict and not ends_well:
                raise Refused("truncated", explain("the file is cut short: it does not end with MCAP's closing "
                                                   "magic bytes (a copy or download that stopped early, or a "
                                                   "recording cut by a crash; `mcap recover` rewrites such a file "
                                                   "whole)"))
            index = FileIndex(path, complete=False)
            try:
                _walk_records(f, size, index)
            except TooCostly:
                raise
            except cut_or_damaged() as exc:
                if strict:
                    raise Refused(
                        "corrupt",
                        explain(
                            "the file is damaged at byte %(tell)s (%(type)s: %(why)s)",
                            tell=f.tell(),
                            type=type(exc).__name__,
                            why=str(exc)[:120],
                        ),
                    ) from None
                if not index.channels:
                    raise NotARecording(explain("%(path)s is damaged before its first message (%(type)s)",
                                                path=path, type=type(exc).__name__)) \
                        from None
            if strict and not index.complete:
                raise Refused("truncated", explain("the file is cut short: its records stop before the footer"))
            return index
    except OSError as exc:
        raise NotARecording(explain("cannot read %(path)s: %(value)s", path=path, value=exc.strerror or exc)) from None


def _ends_with_magic(f) -> bool:
    f.seek(0, 2)
    if f.tell() < 2 * len(MAGIC):
        return False
    f.seek(-len(MAGIC), 2)
    return f.read(len(MAGIC)) == MAGIC


def _walk_records(f, size: int, index: FileIndex) -> None:
    chunk_at: int | None = None
    channels: set[int] = set()
    times: list[int] = []

    def close_chunk() -> None:
        if chunk_at is not None and channels:
            index.chunks.append(ChunkRef(chunk_at, min(times), max(times), frozenset(channels)))

    try:
        for located in bounds.records(f, size, Budget(size), wanted=lambda _channel: False):
            if located.chunk_offset != chunk_at:
                close_chunk()
                chunk_at, channels, times = located.chunk_offset, set(), []
            record = located.record
            if isinstance(record, Message):
                if located.chunk_offset is None:
                    index.loose = True
                else:
                    channels.add(record.channel_id)
                    times.append(record.log_time)
                _count(index, record)
            elif isinstance(record, Footer):
                index.complete = True
            else:
                _describe(index, record)
    finally:
        close_chunk()  # the last whole chunk before a cut or a damaged one


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


def index_of(path: Path, trust_summary: bool = False) -> FileIndex:
    """The file's index, built once (from its summary when trust_summary, i.e. this server wrote
    the file; else by a pass over it); NotARecording for a file that is not MCAP or has nothing
    readable, TooCostly over a bound."""
    try:
        key = _key(path)
    except OSError as exc:
        raise NotARecording(explain("cannot read %(path)s: %(value)s", path=path, value=exc.strerror or exc)) from None
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
            index = (from_summary(path) if trust_summary else None) or walk(path)
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
