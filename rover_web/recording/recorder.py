"""Recorder: one MCAP file being written, by its own thread, from a bounded queue.

The raw taker's thread (ros/raw_taker.py, for the topics) and audit listeners (on request
threads) only `offer` a message: an append to a deque, which never waits and wakes nobody. The
writer takes what came every BATCH_S: a queue.Queue woke it (a lock and a notify on the taking
thread) for every message, once the largest recording cost in a profile of bench/recording.py. A
full queue means the disk or the writer fell behind; the message is counted as dropped for its
topic instead of stalling the thread that took it. The writer thread owns the mcap Writer:
chunked, lz4 (zstd took a third of this thread's time with the camera, for 7 % smaller noisy
frames: docs/recording.md), and flushed (chunk closed, bytes handed to the OS) every FLUSH_S, so a
process killed mid-recording leaves a file readable up to its last flushed chunk
(docs/recording.md#crash-safety).
"""

from __future__ import annotations

import logging
import os
import shutil
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .schema import schema_text

log = logging.getLogger(__name__)

FLUSH_S = 1.0  # at most this much recorded time is lost when the process dies
CHUNK_BYTES = 1024 * 1024  # uncompressed; a full chunk is written before FLUSH_S comes round
BATCH_S = 0.05  # the writer wakes this often, and at once to stop


@dataclass(frozen=True)
class Limits:
    max_bytes: int  # this file
    folder_bytes_other: int  # what the folder's other recordings already take
    folder_max_bytes: int
    min_free_bytes: int


class Recorder:
    def __init__(self, path: Path, channels: dict[str, str], *, limits: Limits, queue_size: int,
                 metadata: dict[str, str], on_progress: Callable[[Recorder], None] | None = None,
                 on_end: Callable[[Recorder], None] | None = None):
        """`channels`: topic -> ros2msg type ("std_msgs/msg/String"); schemas resolved here, so a
        type without its .msg file fails before the file exists (schema.SchemaNotFound)."""
        schemas = {type_name: schema_text(type_name) for type_name in set(channels.values())}
        self.path = path
        self.limits = limits
        self._pending: deque = deque()  # append and popleft are atomic: no lock on the taking thread's path
        self._queue_size = queue_size
        self._wake = threading.Event()
        self._on_progress = on_progress
        self._on_end = on_end
        self.counts: Counter = Counter()  # written, per topic
        self.dropped: Counter = Counter()  # refused by a full queue, per topic
        self.size = 0
        self.stop_reason: str | None = None
        self.error: str | None = None
        self.started_ns = time.time_ns()
        self.ended_ns: int | None = None
        from mcap.writer import CompressionType, Writer  # lz4 and zstandard load with it (reading.py)

        self._stream = open(path, "xb")  # noqa: SIM115 - owned by the writer thread, closed at its end
        self._writer = Writer(self._stream, chunk_size=CHUNK_BYTES, compression=CompressionType.LZ4)
        # profile "ros2" and schema names "pkg/msg/Type", as rosbag2's MCAP plugin writes them.
        self._writer.start(profile="ros2", library="rover_web")
        schema_ids = {t: self._writer.register_schema(name=t, encoding="ros2msg", data=text.encode())
                      for t, text in schemas.items()}
        self.channel_ids: dict[str, int] = {
            topic: self._writer.register_channel(topic=topic, message_encoding="cdr", schema_id=schema_ids[t])
            for topic, t in channels.items()}
        self._topics = {cid: topic for topic, cid in self.channel_ids.items()}
        self._writer.add_metadata("rover_web", metadata)
        self._writer.flush()  # the header on disk now; schemas and channels go in each chunk that uses them
        self._thread = threading.Thread(target=self._run, name=f"recorder-{path.stem}", daemon=True)
        self._thread.start()

    # --- any thread ---

    def offer(self, topic: str, data: bytes, log_time_ns: int | None = None) -> bool:
        """Queue one serialized (CDR) message; never waits. False (and counted) when dropped."""
        if self.stop_reason is not None:
            return False
        if len(self._pending) >= self._queue_size:  # two offers at once may pass by one: still bounded
            self.dropped[topic] += 1
            return False
        self._pending.append((self.channel_ids[topic], log_time_ns or time.time_ns(), data))
        return True

    def stop(self, reason: str, timeout_s: float = 10.0) -> None:
        """Finish the file (summary and footer) and wait for the writer thread, at most timeout_s."""
        if self.stop_reason is None:
            self.stop_reason = reason
        self._wake.set()
        self._thread.join(timeout_s)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    def queued(self) -> int:
        return len(self._pending)

    # --- the writer thread ---

    def _run(self) -> None:
        next_flush = time.monotonic() + FLUSH_S
        try:
            while True:
                self._wake.wait(BATCH_S)
                self._drain()
                if self.stop_reason is not None:
                    self._drain()  # what an offer appended while the reason was being set
                    break
                if time.monotonic() >= next_flush:
                    next_flush = time.monotonic() + FLUSH_S
                    self._writer.flush()
                    self.size = self._stream.tell()
                    reason = self._limit_reached()
                    if reason is not None:
                        self.stop_reason = reason
                        break
                    if self._on_progress is not None:
                        self._on_progress(self)
            self._writer.finish()
        except Exception as exc:  # a full disk, a removed folder: the recording ends and says why
            log.exception("recording %s: write failed", self.path.name)
            self.stop_reason = "write_error"
            self.error = f"{type(exc).__name__}: {exc}"[:300]
        finally:
            self._close()

    def _write(self, item) -> None:
        channel_id, log_time_ns, data = item
        self._writer.add_message(channel_id=channel_id, log_time=log_time_ns, publish_time=log_time_ns,
                                 data=data, sequence=self.counts[self._topics[channel_id]])
        self.counts[self._topics[channel_id]] += 1

    def _drain(self) -> None:
        pending = self._pending
        while pending:
            self._write(pending.popleft())

    def _limit_reached(self) -> str | None:
        limits = self.limits
        if self.size >= limits.max_bytes:
            return "max_size"
        if limits.folder_bytes_other + self.size >= limits.folder_max_bytes:
            return "folder_full"
        if shutil.disk_usage(self.path.parent).free < limits.min_free_bytes:
            return "disk_low"
        return None

    def _close(self) -> None:
        try:
            self._stream.flush()
            os.fsync(self._stream.fileno())  # a finished recording survives a power cut
        except OSError:
            pass
        finally:
            self._stream.close()
        try:
            self.size = self.path.stat().st_size
        except OSError:
            pass
        self.ended_ns = time.time_ns()
        if self._on_end is not None:
            try:
                self._on_end(self)
            except Exception:
                log.exception("recording %s: could not note its end", self.path.name)
