"""What reading one MCAP file may cost, and the reader that keeps to it (issue 40, third security round).

An MCAP file says how big its chunks are and what is in them; a file from elsewhere (an upload, a
file copied into the folder) may lie. mcap's own reader decompresses a zstd chunk to whatever size
it declares and an lz4 chunk to whatever it holds, and its schemas go to a parser whose duplicate
check is quadratic. So every read of a file here (the upload's check, the replay view, the timeline,
`flask replay`) goes through this module, under one Budget per read:

- a chunk: its declared size, its compressed length and what it actually holds are each at most
  CHUNK_MAX, decompressed by bounded stream decompressors (zstandard's stream reader, lz4.frame's
  LZ4FrameDecompressor with max_length), never by a whole-buffer call; a chunk holding more than it
  declares is refused at the first byte over;
- the whole read: at most max(READ_MIN, READ_RATIO x the file's size) bytes decompressed in all, and
  TIME_S seconds;
- a message: at most MESSAGE_MAX bytes;
- a schema: at most SCHEMA_MAX bytes and SCHEMA_FIELDS field or constant lines, checked before any
  parser sees it.

A file over one is refused with TooCostly, whose `code` names the bound (a 422 at the routes).
"""

from __future__ import annotations

import struct
import time
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Footer, Message, Schema

from rover_web.web.api_messages import Text, explain

from .reading import Refused

MIB = 1 << 20
CHUNK_MAX = 48 * MIB  # a 4K rgb8 frame is 25 MB; rover_web writes 1 MB chunks
MESSAGE_MAX = 48 * MIB
READ_MIN = 512 * MIB
READ_RATIO = 64  # lz4 on camera frames and telemetry: 2-10x; the simulator's bars ~30x; a bomb thousands
TIME_S = 20.0
SCHEMA_MAX = 256 * 1024  # rosbag2's texts: Odometry 5 KB, the largest Nav2 action ~40 KB
SCHEMA_FIELDS = 2000  # Odometry's full text has 32; the parser's duplicate check is quadratic in this
DECODE_MAX = MIB  # a message decoded into Python objects for the timeline, plots, diagnostics
MIN_ELEMENT = 4  # bytes: an array of smaller messages is decoded into more objects than bytes

_HEAD = struct.Struct("<BQ")
_CHUNK_HEAD = struct.Struct("<QQQI")  # start, end, uncompressed size, uncompressed crc
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel, sequence, log time, publish time
_BLOCK = 2 * MIB


class TooCostly(Refused):
    """A file over one of the bounds above; `code` names it."""


@dataclass
class Budget:
    """The allowance of one read of one file."""

    file_size: int
    decompressed: int = 0
    started: float = field(default_factory=time.monotonic)

    @property
    def most(self) -> int:
        return max(READ_MIN, READ_RATIO * self.file_size)

    def spend(self, nbytes: int) -> None:
        self.decompressed += nbytes
        if self.decompressed > self.most:
            raise TooCostly(
                "read_budget",
                explain(
                    "reading this file would decompress more than %(value)s MB (at "
                    "most %(read_ratio)s times the file's size, or %(value2)s MB): "
                    "refused",
                    value=self.most // MIB,
                    read_ratio=READ_RATIO,
                    value2=READ_MIN // MIB,
                ),
            )
        self.check_time()

    def check_time(self) -> None:
        if time.monotonic() - self.started > TIME_S:
            raise TooCostly("time_budget", explain("reading this file took more than %(time_s)s s: refused",
                                                   time_s=format(TIME_S, "g")))


def check_schema(schema: Schema) -> None:
    if len(schema.data) > SCHEMA_MAX:
        raise TooCostly(
            "schema_too_large",
            explain(
                "schema %(name)s is %(count)s bytes, more than %(schema_max)s",
                name=repr(schema.name[:80]),
                count=len(schema.data),
                schema_max=SCHEMA_MAX,
            ),
        )
    if schema.data.count(b"\n") + 1 > SCHEMA_FIELDS and _fields(schema.data) > SCHEMA_FIELDS:
        raise TooCostly("schema_too_many_fields", explain("schema %(name)s declares more than %(schema_fields)s "
                                                          "fields",
                                                          name=repr(schema.name[:80]), schema_fields=SCHEMA_FIELDS))


def _fields(text: bytes) -> int:
    count = 0
    for line in text.split(b"\n"):
        line = line.strip()
        if line and not line.startswith((b"#", b"===", b"MSG:")):
            count += 1
    return count


def _refuse_chunk(declared: int, held: Text) -> TooCostly:
    return TooCostly("chunk_too_large", explain("a chunk %(held)s; a chunk may hold at most %(value)s MB (it "
                                                "declares %(declared)s bytes)",
                                                held=held, value=CHUNK_MAX // MIB, declared=declared))


def decompress(compression: str, data: bytes, declared: int) -> bytes | bytearray:
    """The chunk's content, never more than min(declared, CHUNK_MAX) bytes made."""
    if declared > CHUNK_MAX:
        raise _refuse_chunk(declared, explain("declares %(mb)s MB", mb=declared // MIB))
    most = declared
    if compression == "":
        if len(data) != declared:
            raise Refused("corrupt", explain("an uncompressed chunk's length is not the size it declares"))
        return data
    if compression == "zstd":
        import zstandard

        out = bytearray(most + 1)  # one buffer, filled in place: one byte more than declared says "more"
        view = memoryview(out)
        filled = 0
        with zstandard.ZstdDecompressor().stream_reader(data, read_across_frames=True) as reader:
            while filled <= most:  # a few MB a call: other threads (the e-stop's request) get the GIL between
                n = reader.readinto(view[filled:filled + _BLOCK])
                if not n:
                    break
                filled += n
        view.release()
        if filled > most:
            raise _refuse_chunk(declared, explain("holds more than it declares"))
        del out[filled:]
        return out
    if compression == "lz4":
        import lz4.frame

        decompressor = lz4.frame.LZ4FrameDecompressor()
        out = decompressor.decompress(data, max_length=most + 1)
        if len(out) > most or (not decompressor.eof and not decompressor.needs_input):
            raise _refuse_chunk(declared, explain("holds more than it declares"))
        return out
    raise Refused("corrupt", explain("a chunk is compressed with %(compression)s, which this server does not read",
                                     compression=repr(compression[:20])))


def read_chunk(f, offset: int, file_size: int, budget: Budget) -> bytes:
    """The content of the Chunk record at `offset` (of its opcode), bounded; Refused (corrupt) for
    anything else at that offset, TooCostly over a bound."""
    f.seek(offset)
    head = f.read(_HEAD.size)
    if len(head) < _HEAD.size:
        raise Refused("corrupt", explain("no record at byte %(offset)s", offset=offset))
    opcode, length = _HEAD.unpack(head)
    if opcode != Opcode.CHUNK:
        raise Refused("corrupt", explain("the record at byte %(offset)s is not a chunk (opcode %(opcode)s)",
                                         offset=offset, opcode=format(opcode, "#x")))
    return _chunk_content(f, offset + _HEAD.size, length, file_size, budget)


def _chunk_content(f, at: int, length: int, file_size: int, budget: Budget) -> bytes:
    if at + length > file_size:
        raise Refused("truncated", explain("a chunk runs past the end of the file"))
    if length > CHUNK_MAX + 1024:
        raise _refuse_chunk(-1, explain("is %(mb)s MB compressed", mb=length // MIB))
    f.seek(at)
    record = f.read(length)
    try:
        _start, _end, declared, crc = _CHUNK_HEAD.unpack_from(record, 0)
        stream = ReadDataStream(_View(record, _CHUNK_HEAD.size))
        compression = stream.read_prefixed_string()
        data_length = stream.read8()
        data = record[_CHUNK_HEAD.size + 4 + len(compression.encode()) + 8:]
    except (struct.error, UnicodeDecodeError, EOFError, ValueError):
        raise Refused("corrupt", explain("a chunk's header is damaged")) from None
    if data_length != len(data):
        raise Refused("corrupt", explain("a chunk's data length does not match its record"))
    if declared > CHUNK_MAX:
        raise _refuse_chunk(declared, explain("declares %(mb)s MB", mb=declared // MIB))
    budget.spend(declared)
    content = decompress(compression, data, declared)
    if len(content) != declared:
        raise Refused("corrupt", explain("a chunk holds less than the size it declares"))
    if crc and zlib.crc32(content) != crc:
        raise Refused("corrupt", explain("a chunk's CRC does not match its content"))
    return content


class _View:
    """The bytes after `start`, as a file for mcap's ReadDataStream."""

    def __init__(self, data: bytes, start: int):
        self._data, self._at = data, start

    def read(self, n: int) -> bytes:
        out = self._data[self._at:self._at + n]
        self._at += len(out)
        return out


def parse_records(content: bytes, wanted: Callable[[int], bool] | None = None,
                  budget: Budget | None = None) -> Iterator[Schema | Channel | Message]:
    """The records of a chunk's content. A message's bytes are copied only when `wanted(channel)`
    (None: all); others carry b"" (their time and channel are what an index needs)."""
    at, end = 0, len(content)
    view = memoryview(content)
    seen = 0
    while at < end:
        if end - at < _HEAD.size:
            raise Refused("corrupt", explain("a chunk ends inside a record's header"))
        opcode, length = _HEAD.unpack_from(content, at)
        at += _HEAD.size
        if at + length > end:
            raise Refused("corrupt", explain("a record runs past the end of its chunk"))
        if opcode == Opcode.MESSAGE:
            yield message_of(view, at, length, wanted)
        elif opcode == Opcode.SCHEMA:
            yield schema_of(bytes(view[at:at + length]))
        elif opcode == Opcode.CHANNEL:
            yield Channel.read(ReadDataStream(_View(bytes(view[at:at + length]), 0)))
        at += length
        seen += 1
        if budget is not None and not seen % 4096:
            budget.check_time()


def message_of(view, at: int, length: int, wanted: Callable[[int], bool] | None) -> Message:
    if length < _MESSAGE_HEAD.size:
        raise Refused("corrupt", explain("a message record is shorter than its header"))
    size = length - _MESSAGE_HEAD.size
    if size > MESSAGE_MAX:
        raise TooCostly("message_too_large", explain("a message is %(value)s MB, more than %(value2)s MB",
                                                     value=size // MIB, value2=MESSAGE_MAX // MIB))
    channel, sequence, log_time, publish_time = _MESSAGE_HEAD.unpack_from(view, at)
    data = bytes(view[at + _MESSAGE_HEAD.size:at + length]) if wanted is None or wanted(channel) else b""
    return Message(channel_id=channel, sequence=sequence, log_time=log_time, publish_time=publish_time, data=data)


def schema_of(record: bytes) -> Schema:
    try:
        schema = Schema.read(ReadDataStream(_View(record, 0)))
    except (struct.error, UnicodeDecodeError, EOFError, ValueError):
        raise Refused("corrupt", explain("a schema record is damaged")) from None
    check_schema(schema)
    return schema


@dataclass
class Located:
    """A record read by records(), with the offset of the chunk it came from (None: outside one)."""

    record: object
    chunk_offset: int | None


def records(f, file_size: int, budget: Budget, wanted: Callable[[int], bool] | None = None) -> Iterator[Located]:
    """Every record from the file's start (after the magic), chunks opened, under `budget`; stops
    quietly at a cut end (the caller sees no Footer), Refused for damage, TooCostly over a bound."""
    at = 8
    f.seek(at)
    while True:
        head = f.read(_HEAD.size)
        if len(head) < _HEAD.size:
            return
        opcode, length = _HEAD.unpack(head)
        body = at + _HEAD.size
        if body + length > file_size:
            return  # cut inside this record
        if opcode == Opcode.CHUNK:
            content = _chunk_content(f, body, length, file_size, budget)
            for record in list(parse_records(content, wanted, budget)):  # a damaged chunk counts for nothing
                yield Located(record, at)
        elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
            if opcode == Opcode.MESSAGE and length > MESSAGE_MAX + _MESSAGE_HEAD.size:
                raise TooCostly("message_too_large", explain("a message is %(value)s MB, more than %(value2)s MB",
                                                             value=length // MIB, value2=MESSAGE_MAX // MIB))
            if opcode == Opcode.SCHEMA and length > SCHEMA_MAX + 1024:
                raise TooCostly("schema_too_large", explain("a schema record is %(length)s bytes, more than "
                                                            "%(schema_max)s",
                                                            length=length, schema_max=SCHEMA_MAX))
            raw = f.read(length)
            if opcode == Opcode.MESSAGE:
                yield Located(message_of(memoryview(raw), 0, length, wanted), None)
            elif opcode == Opcode.SCHEMA:
                yield Located(schema_of(raw), None)
            else:
                yield Located(Channel.read(ReadDataStream(_View(raw, 0))), None)
        elif opcode == Opcode.FOOTER:
            yield Located(Footer.read(ReadDataStream(_View(f.read(length), 0))), None)
            return
        budget.check_time()
        at = body + length
        f.seek(at)


def amplifies(schema_name: str, text: str) -> bool:
    """True when the schema has an array of messages each smaller than MIN_ELEMENT bytes in CDR: its
    decoding would make more Python objects than the message has bytes (the review's array of empty
    messages: 8 MB took 9 s and 1 GB to decode)."""
    from mcap_ros2._dynamic import _for_each_msgdef

    specs: dict = {}

    def keep(full_name, short_name, msgdef):
        specs[full_name] = specs[short_name] = msgdef

    _for_each_msgdef(schema_name, text, keep)
    sizes: dict[str, int] = {}

    def min_size(key: str, depth: int = 0) -> int:
        if key in sizes:
            return sizes[key]
        spec = specs.get(key)
        if spec is None or depth > 32:
            return 8  # builtin_interfaces Time/Duration, or a type the decoder fails on anyway
        total = 0
        for f in spec.fields:
            t = f.type
            if t.is_array and not t.is_fixed_size_array():
                total += 4
            elif t.is_primitive_type():
                total += _PRIMITIVE.get(t.type, 4) * (t.array_size or 1 if t.is_array else 1)
            else:
                total += min_size(f"{t.pkg_name}/{t.type}", depth + 1) * (t.array_size or 1 if t.is_array else 1)
        sizes[key] = total or 1  # an empty message is one placeholder byte
        return sizes[key]

    for spec in list(specs.values()):
        for f in spec.fields:
            t = f.type
            if t.is_array and not t.is_primitive_type() and min_size(f"{t.pkg_name}/{t.type}") < MIN_ELEMENT:
                return True
    return False


_PRIMITIVE = {"bool": 1, "byte": 1, "char": 1, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4,
              "uint32": 4, "float32": 4, "int64": 8, "uint64": 8, "float64": 8, "string": 4, "wstring": 4}
