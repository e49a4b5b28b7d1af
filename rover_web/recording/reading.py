"""Reading a recording back, whole or cut short (a SIGKILL or a power loss before its footer).

mcap's seeking reader needs the summary at the end of the file; a recording whose process died
has none. The non-seeking StreamReader reads records in order from the start and raises EndOfFile
where the bytes stop: everything before the last complete chunk is there (the writer closes a
chunk at least every recorder.FLUSH_S), so reading until that point is reading all that survived.
"""

from __future__ import annotations

import functools
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from mcap.exceptions import EndOfFile, InvalidMagic, McapError
from mcap.records import Channel, Footer, Message, Schema

from rover_web.web.api_messages import explain

MAGIC = b"\x89MCAP0\r\n"


# mcap's stream reader brings lz4 and zstandard (1.5 MB): they load when a recording is first read
# or written, not at start (issue 32: idle RSS); hence a function, not a module-level tuple.
@functools.cache
def cut_or_damaged() -> tuple[type[BaseException], ...]:
    """What the stream reader raises where the bytes stop or stop making sense (CRCValidationError
    is a ValueError; the lz4 package says a damaged or cut frame with a RuntimeError)."""
    import zstandard
    return (EndOfFile, InvalidMagic, McapError, struct.error, zlib.error, zstandard.ZstdError, ValueError,
            RuntimeError)


class NotARecording(ValueError):
    """Not an MCAP file at all, or damaged before its first message; the message says which."""


class Refused(NotARecording):
    """A file refused by a strict read (file_index.walk) or over a bound (bounds.TooCostly): `code`
    is not_mcap, truncated, corrupt or the bound's name."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


@dataclass
class Outcome:
    complete: bool = False  # the footer was read: the file was finished properly
    messages: int = 0


def read_messages(path: Path, outcome: Outcome | None = None) -> Iterator[tuple[Schema | None, Channel, Message]]:
    """Every message in file order, with its channel and schema; stops quietly at a cut end
    (outcome.complete says whether the footer was there). NotARecording for anything that is
    not MCAP; a damaged chunk in the middle ends the reading like a cut. Under the bounds of
    bounds.py: bounds.TooCostly (a Refused) for a file over one, wherever it is met."""
    from .bounds import Budget, TooCostly, records

    outcome = outcome if outcome is not None else Outcome()
    try:
        with open(path, "rb") as f:
            if f.read(len(MAGIC)) != MAGIC:
                raise NotARecording(explain("%(path)s is not an MCAP file (it does not start with the MCAP magic "
                                            "bytes)",
                                            path=path))
            size = f.seek(0, 2)
            schemas: dict[int, Schema] = {}
            channels: dict[int, Channel] = {}
            try:
                for located in records(f, size, Budget(size)):
                    record = located.record
                    if isinstance(record, Schema):
                        schemas[record.id] = record
                    elif isinstance(record, Channel):
                        channels[record.id] = record
                    elif isinstance(record, Message):
                        channel = channels.get(record.channel_id)
                        if channel is None:
                            continue
                        outcome.messages += 1
                        yield schemas.get(channel.schema_id), channel, record
                    elif isinstance(record, Footer):
                        outcome.complete = True
                if not outcome.complete and outcome.messages == 0 and not channels:
                    raise NotARecording(explain("%(path)s is cut before its first message", path=path))
            except TooCostly:
                raise
            except cut_or_damaged() as exc:
                if outcome.messages == 0 and not channels:
                    raise NotARecording(explain("%(path)s is damaged before its first message (%(type)s)",
                                                path=path, type=type(exc).__name__)) \
                        from None
                # Cut short: what came before is what survived.
    except OSError as exc:
        raise NotARecording(explain("cannot read %(path)s: %(value)s", path=path, value=exc.strerror or exc)) from None
