"""An MCAP file from elsewhere, uploaded to be replayed here (POST /api/recordings/upload).

Operators upload, as they record: a file takes the same disk as a recording (it counts towards
ROVER_WEB_RECORDINGS_MAX_MB and the free-disk floor), and what it holds is what the robot's own
recordings hold; viewers only read, and deleting stays an admin's.

The body is the file itself (Content-Type: application/octet-stream), at most
ROVER_WEB_RECORDING_UPLOAD_MAX_MB. It is written to `.incoming/` inside the recordings folder,
flushed, then read whole (file_index.walk, strict: every chunk decompressed and its CRC checked)
and only then renamed into the folder, so the folder never holds a half-written or unreadable
upload: a body that is cut short, damaged, not MCAP or holds no ROS 2 message is a 4xx and its
temporary file is removed; one left by a process that died mid-upload is removed at the next start.
"""

from __future__ import annotations

import json
import os
import secrets
import time
from pathlib import Path

from werkzeug.exceptions import ClientDisconnected, RequestEntityTooLarge

from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError

from .file_index import Refused, remember, walk

INCOMING = ".incoming"
BLOCK = 1024 * 1024


def clear_incoming(folder: Path) -> None:
    """At start: what an upload cut by a crash left behind."""
    for leftover in (folder / INCOMING).glob("*.part"):
        leftover.unlink(missing_ok=True)


def receive(service, request, name: str, by: str) -> dict:
    """Store the uploaded file (the request's body) as a recording; its status (201), or ApiError
    saying why not."""
    limit = service.upload_max_bytes
    content_length = request.content_length
    if content_length is not None and content_length > limit:
        raise _too_large(limit)  # before request.stream, which would refuse it in words of its own
    service.check_room(content_length or 0)
    incoming = service.folder / INCOMING
    incoming.mkdir(mode=0o700, parents=True, exist_ok=True)
    part = incoming / f"{secrets.token_hex(8)}.part"
    try:
        size = _copy(request.stream, part, limit)
        if content_length is None:
            service.check_room(size)  # a streamed body said its size only now
        if size == 0:
            raise ApiError(422, "not_mcap", "the body is empty: send the MCAP file itself as the body "
                                            "(Content-Type: application/octet-stream)")
        try:
            index = walk(part, strict=True)
        except Refused as exc:
            raise ApiError(422, exc.code, text_of(exc)) from None
        decodable = [t for t, info in index.topics().items() if info["decodable"]]
        if not decodable:
            raise ApiError(422, "not_ros2", "this MCAP file holds no ROS 2 message (a cdr channel with a ros2msg "
                                            "schema): the replay view shows ROS 2 recordings")
        recording_id = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()) + "-up-" + secrets.token_hex(3)
        path = service.folder / f"{recording_id}.mcap"
        os.rename(part, path)  # same filesystem: the file appears whole or not at all
        remember(path, index)
        topics = index.topics()
        service.add_uploaded({
            "id": recording_id, "name": name, "file": path.name, "started_at": index.start_ns / 1e9,
            "ended_at": index.end_ns / 1e9, "state": "stopped", "started_by": by, "size": size,
            "selection": json.dumps({"topics": "uploaded", "uploaded": {"by": by, "at": time.time(),
                                                                        "complete": index.complete}}),
            "topics": {topic: info["type"] for topic, info in topics.items()},
            "counts": {topic: info["count"] for topic, info in topics.items()}})
        return service.status(recording_id)
    finally:
        part.unlink(missing_ok=True)


def _copy(stream, part: Path, limit: int) -> int:
    size = 0
    try:
        # 0600 from its creation (the folder is 0700): an upload is someone's data until it is checked.
        with os.fdopen(os.open(part, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600), "wb") as out:
            while True:
                block = stream.read(BLOCK)
                if not block:
                    break
                size += len(block)
                if size > limit:
                    raise _too_large(limit)
                out.write(block)
            out.flush()
            os.fsync(out.fileno())
    except RequestEntityTooLarge:
        raise _too_large(limit) from None
    except ClientDisconnected:
        raise ApiError(400, "upload_incomplete", "the upload stopped before the whole body arrived; "
                                                 "nothing was stored") from None
    except OSError as exc:
        raise ApiError(507, "cannot_write", "cannot write the upload: %(value)s",
                       value=exc.strerror or exc) from None
    return size


def _too_large(limit: int) -> ApiError:
    return ApiError(413, "upload_too_large", "the file is larger than ROVER_WEB_RECORDING_UPLOAD_MAX_MB (%(value)s "
                                             "MB); nothing was stored",
                    value=format(limit / (1024 * 1024), "g"))
