"""RecordingService: one robot's recordings. Start picks the topics and subscribes raw, the
Recorder writes, stop (or a limit) ends it; the index keeps the list across restarts.

One recording at a time per robot: two would store the same messages twice and halve the
disk budget, and "what happened at 14:32" has one answer file (a second start is 409).
"""

from __future__ import annotations

import json
import logging
import secrets
import shutil
import threading
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from rover_web.core.state import Rover
from rover_web.ros.graph import matching_qos, topic_types
from rover_web.ros.raw import string_cdr
from rover_web.ros.raw_taker import RawTaker
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError

from . import file_index, upload
from .recorder import Limits, Recorder
from .schema import SchemaNotFound, schema_text
from .store import RecordingIndex

log = logging.getLogger(__name__)

AUDIT_TOPIC = "/rover_web/audit"
AUDIT_TYPE = "std_msgs/msg/String"
IMAGE_TYPES = frozenset({"sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"})
MB = 1024 * 1024
SUBSCRIPTION_DEPTH = 50  # keep-last per topic inside rclpy, before the callback hands it on


@dataclass
class Selection:
    """What a start request asked for: "all", a preset or a list; the camera or not; a name."""

    topics: str | list[str]
    camera: bool = False
    name: str = ""


@dataclass
class _Active:
    id: str
    recorder: Recorder
    subscriptions: list = field(default_factory=list)
    unsubscribes: list = field(default_factory=list)
    torn_down: bool = False


class RecordingService:
    def __init__(self, rover: Rover, folder: Path, index: RecordingIndex, *, extra_audit=()):
        self.rover = rover
        self.folder = folder
        self.index = index
        config = rover.config
        self.presets = parse_presets(config["ROVER_WEB_RECORDING_PRESETS"])
        self.max_bytes = int(config["ROVER_WEB_RECORDING_MAX_MB"] * MB)
        self.folder_max_bytes = int(config["ROVER_WEB_RECORDINGS_MAX_MB"] * MB)
        self.min_free_bytes = int(config["ROVER_WEB_RECORDINGS_MIN_FREE_MB"] * MB)
        self.camera_period_s = 1.0 / config["ROVER_WEB_RECORDING_CAMERA_MAX_HZ"]
        self.queue_size = config["ROVER_WEB_RECORDING_QUEUE"]
        self.upload_max_bytes = int(config["ROVER_WEB_RECORDING_UPLOAD_MAX_MB"] * MB)
        self._audit_hubs = [rover.audit, *[hub for hub in extra_audit if hub is not rover.audit]]
        self._lock = threading.Lock()
        self._active: _Active | None = None
        self.stops: Counter[str] = Counter()  # recordings ended, by stop_reason: for /metrics (rover_web/metrics)
        self._taker: RawTaker | None = None  # made at the first recording
        index.reconcile(folder, rover.robot.name)
        upload.clear_incoming(folder)

    # --- start and stop ---

    def start(self, selection: Selection, by: str) -> dict:
        with self._lock:
            if self._active is not None:
                raise ApiError(409, "recording_in_progress", "recording %(id)s is running on %(name)s: stop it first "
                                                             "(one recording at a time per robot)",
                               id=self._active.id, name=self.rover.robot.name)
            self.check_room()
            channels, skipped, left_out = self._choose(selection)
            recording_id = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()) + "-" + secrets.token_hex(3)
            path = self.folder / f"{recording_id}.mcap"
            limits = Limits(self.max_bytes, self._folder_bytes(), self.folder_max_bytes, self.min_free_bytes)
            metadata = {"id": recording_id, "name": selection.name, "robot": self.rover.robot.name,
                        "started_by": by}
            try:
                recorder = Recorder(path, {**channels, AUDIT_TOPIC: AUDIT_TYPE}, limits=limits,
                                    queue_size=self.queue_size, metadata=metadata, on_progress=self._progress,
                                    on_end=self._ended)
            except OSError as exc:
                path.unlink(missing_ok=True)
                raise ApiError(507, "cannot_write", "cannot write %(path)s: %(value)s",
                               path=path, value=exc.strerror or exc) from None
            active = _Active(recording_id, recorder)
            self.index.add({
                "id": recording_id, "robot": self.rover.robot.name, "name": selection.name, "file": path.name,
                "started_at": recorder.started_ns / 1e9, "state": "recording", "started_by": by,
                "selection": json.dumps({"topics": selection.topics, "camera": selection.camera,
                                         "skipped": skipped, "left_out": left_out}),
                "topics": {**channels, AUDIT_TOPIC: AUDIT_TYPE}})
            self._active = active
        try:
            self._subscribe(active, channels)
        except Exception as exc:  # rclpy refused a subscription: end the file cleanly, say why
            log.exception("recording %s: could not subscribe", recording_id)
            self._teardown(active)
            active.recorder.error = f"{type(exc).__name__}: {exc}"[:300]
            active.recorder.stop("subscribe_failed")
            raise ApiError(
                503, "subscribe_failed", "could not subscribe to the topics: %(why)s", why=text_of(exc)
            ) from None
        self.rover.audit.record("recording.start", by=by, detail=f"recording {recording_id} started",
                                recording=recording_id, topics=len(channels))
        return self.status(recording_id)

    def stop(self, recording_id: str, by: str) -> dict:
        with self._lock:
            active = self._active
        if self.index.get(recording_id) is None or self.index.get(recording_id)["robot"] != self.rover.robot.name:
            raise ApiError(404, "not_found", "no recording %(recording_id)s", recording_id=repr(recording_id))
        if active is None or active.id != recording_id:
            return self.status(recording_id)  # already stopped: stopping again changes nothing
        self.rover.audit.record("recording.stop", by=by, detail=f"recording {recording_id} stopped",
                                recording=recording_id)
        self.index.update(recording_id, stopped_by=by)
        self._teardown(active)
        active.recorder.stop("requested")
        return self.status(recording_id)

    def shutdown(self) -> None:
        with self._lock:
            active = self._active
        if active is not None:
            self._teardown(active)
            active.recorder.stop("shutdown")

    # --- read ---

    def status(self, recording_id: str) -> dict:
        row = self.index.get(recording_id)
        if row is None or row["robot"] != self.rover.robot.name:
            raise ApiError(404, "not_found", "no recording %(recording_id)s", recording_id=repr(recording_id))
        active = self._active
        return self._view(row, active.recorder if active is not None and active.id == recording_id else None)

    def list(self) -> list[dict]:
        active = self._active
        return [self._view(row, active.recorder if active is not None and active.id == row["id"] else None)
                for row in self.index.all(self.rover.robot.name)]

    def path_of(self, recording_id: str) -> Path:
        row = self.index.get(recording_id)
        if row is None or row["robot"] != self.rover.robot.name:
            raise ApiError(404, "not_found", "no recording %(recording_id)s", recording_id=repr(recording_id))
        return self.folder / row["file"]

    def delete(self, recording_id: str, by: str) -> None:
        path = self.path_of(recording_id)
        active = self._active
        if active is not None and active.id == recording_id:
            raise ApiError(409, "recording_in_progress", "this recording is running: stop it before deleting it")
        path.unlink(missing_ok=True)
        file_index.forget(path)
        self.index.delete(recording_id)
        self.rover.audit.record("recording.delete", by=by, detail=f"recording {recording_id} deleted",
                                recording=recording_id)

    # --- internals ---

    def _choose(self, selection: Selection) -> tuple[dict[str, str], list[str], list[str]]:
        """(topic -> type to record, topics skipped (not on the graph, or no .msg installed), image
        topics left out because the camera was not asked for)."""
        graph = topic_types(self.rover.runtime)
        namespace = self.rover.robot.namespace
        if selection.topics == "all":
            wanted = [t for t in sorted(graph) if not namespace or t.startswith(namespace + "/")]
            strict = False
        elif isinstance(selection.topics, str):
            preset = selection.topics.removeprefix("preset:")
            if preset not in self.presets:
                raise ApiError(400, "unknown_preset", "no preset %(preset)s; presets: %(value)s "
                                                      "(ROVER_WEB_RECORDING_PRESETS)",
                               preset=repr(preset), value=', '.join(sorted(self.presets)) or 'none')
            wanted = [self.rover.resolve(t) for t in self.presets[preset]]
            strict = False
        else:
            wanted, strict = [self.rover.resolve(t) for t in selection.topics], True
        channels: dict[str, str] = {}
        skipped: list[str] = []
        left_out: list[str] = []
        for topic in wanted:
            types = graph.get(topic)
            type_name = types[0] if types else None
            if type_name is not None and type_name in IMAGE_TYPES and not selection.camera:
                left_out.append(topic)
                continue
            try:
                if type_name is not None:
                    schema_text(type_name)
            except SchemaNotFound:
                type_name = None
            if type_name is None:
                skipped.append(topic)
            elif topic != AUDIT_TOPIC:
                channels[topic] = type_name
        if strict and skipped:
            raise ApiError(422, "unknown_topic", "not recordable (no publisher seen, or its message definition is "
                                                 "not installed): %(skipped)s", skipped=', '.join(skipped[:10]))
        return channels, skipped, left_out

    def _subscribe(self, active: _Active, channels: dict[str, str]) -> None:
        runtime = self.rover.runtime
        recorder = active.recorder
        if self._taker is None:
            # Not the app's executor: its thread serves teleop and the e-stop, and rebuilt its whole
            # wait set for every recorded message (ros/raw_taker.py says what that cost).
            self._taker = RawTaker(runtime, "recorder", namespace=self.rover.robot.namespace)
        for topic, type_name in channels.items():
            if type_name in IMAGE_TYPES:
                callback = _throttled(recorder, topic, self.camera_period_s)
            else:
                def callback(data: bytes, received_ns: int, topic=topic) -> None:
                    recorder.offer(topic, data, received_ns)
            # Raw: the CDR bytes as they came; they go into the file unchanged, logged at the time the
            # middleware received them (as rosbag2 logs them), not when this thread took them.
            active.subscriptions.append(self._taker.subscribe(type_name, topic, callback,
                                                              matching_qos(runtime, topic, SUBSCRIPTION_DEPTH)))

        def audit(record: dict) -> None:
            stamp = record["timestamp"]
            recorder.offer(AUDIT_TOPIC, string_cdr(json.dumps(record, separators=(",", ":"))),
                           stamp["sec"] * 1_000_000_000 + stamp["nsec"])
        active.unsubscribes = [hub.subscribe(audit) for hub in self._audit_hubs]

    def _teardown(self, active: _Active) -> None:
        with self._lock:
            if active.torn_down:
                return
            active.torn_down = True
        for unsubscribe in active.unsubscribes:
            unsubscribe()
        for subscription in active.subscriptions:
            try:
                self._taker.unsubscribe(subscription)
            except Exception:  # shutting down: the node may be gone already
                log.debug("could not destroy a recording subscription", exc_info=True)

    def _progress(self, recorder: Recorder) -> None:
        # Every flush: the list shows live numbers, and a crash leaves the last ones in the index.
        self.index.update(recorder.path.stem, counts=dict(recorder.counts), dropped=dict(recorder.dropped),
                          size=recorder.size)

    def _ended(self, recorder: Recorder) -> None:
        with self._lock:
            active = self._active
        if active is not None and active.recorder is recorder:
            self._teardown(active)
        self.index.update(recorder.path.stem, state="stopped", stop_reason=recorder.stop_reason,
                          error=recorder.error, ended_at=recorder.ended_ns / 1e9, size=recorder.size,
                          counts=dict(recorder.counts), dropped=dict(recorder.dropped))
        with self._lock:
            if self._active is active:
                self._active = None
        self.stops[recorder.stop_reason or "unknown"] += 1
        if recorder.stop_reason not in ("requested", "shutdown"):
            log.warning("recording %s stopped: %s", recorder.path.stem, recorder.stop_reason)

    def check_room(self, adding: int = 0) -> None:
        """507 unless the folder and the disk have room for a recording (or an upload of `adding` bytes)."""
        self.folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        if self._folder_bytes() + adding >= self.folder_max_bytes:
            if adding:
                raise ApiError(507, "folder_full", "the recordings take ROVER_WEB_RECORDINGS_MAX_MB already with this "
                                                   "file: delete some first")
            raise ApiError(
                507, "folder_full", "the recordings take ROVER_WEB_RECORDINGS_MAX_MB already: delete some first"
            )
        if shutil.disk_usage(self.folder).free - adding < self.min_free_bytes:
            if adding:
                raise ApiError(507, "disk_low", "the disk has less free space than ROVER_WEB_RECORDINGS_MIN_FREE_MB "
                                                "once this file is stored")
            raise ApiError(507, "disk_low", "the disk has less free space than ROVER_WEB_RECORDINGS_MIN_FREE_MB")

    def add_uploaded(self, row: dict) -> None:
        """An uploaded file's row (upload.py has checked and renamed the file)."""
        self.index.add({**row, "robot": self.rover.robot.name})
        self.rover.audit.record("recording.upload", by=row["started_by"],
                                detail=f"recording {row['id']} uploaded ({row['size']} bytes)", recording=row["id"])

    def _folder_bytes(self) -> int:
        return sum(p.stat().st_size for p in self.folder.glob("*.mcap") if p.is_file())

    def _view(self, row: dict, recorder: Recorder | None) -> dict:
        selection = json.loads(row["selection"] or "{}")
        counts, dropped, size = row["counts"], row["dropped"], row["size"]
        ended = row["ended_at"]
        if recorder is not None:
            counts, dropped, size = dict(recorder.counts), dict(recorder.dropped), recorder.size
        duration = (ended if ended is not None else time.time()) - row["started_at"]
        return {
            "id": row["id"], "name": row["name"], "robot": row["robot"], "state": row["state"],
            "stop_reason": row["stop_reason"], "error": row["error"],
            "started_at": row["started_at"], "ended_at": ended, "duration_s": round(max(0.0, duration), 3),
            "size": size, "started_by": row["started_by"], "stopped_by": row["stopped_by"],
            "selection": selection.get("topics"), "camera": selection.get("camera", False),
            "topics": row["topics"], "counts": counts, "messages": sum(counts.values()), "dropped": dropped,
            "skipped": selection.get("skipped", []), "left_out": selection.get("left_out", []),
            "source": "uploaded" if "uploaded" in selection else "recorded",
            "file": f"/api/recordings/{row['id']}/file",
        }


def _throttled(recorder: Recorder, topic: str, period_s: float):
    """At most one frame per period_s on average. A token bucket (room for 1.5 frames), not a
    minimum gap: a 10 fps camera recorded at 10 Hz arrives with jitter, and a minimum gap of
    exactly 0.1 s dropped a third of its frames (bench/recording.py). Timed by each frame's
    reception, not by when it was taken: frames that waited and are taken together are still
    10 Hz frames."""
    bucket = {"tokens": 1.5, "at": None}  # full: the first frames pass

    def callback(data: bytes, received_ns: int) -> None:
        now = received_ns / 1e9 if received_ns else time.time()
        last = bucket["at"] if bucket["at"] is not None else now
        bucket["tokens"] = min(1.5, bucket["tokens"] + max(0.0, now - last) / period_s)
        bucket["at"] = now
        if bucket["tokens"] >= 1.0:
            bucket["tokens"] -= 1.0
            recorder.offer(topic, data, received_ns)
    return callback


def parse_presets(entries: list[str]) -> dict[str, list[str]]:
    """ROVER_WEB_RECORDING_PRESETS: ["name=/a /b", ...] -> {"name": ["/a", "/b"]}; ValueError if malformed."""
    presets: dict[str, list[str]] = {}
    for entry in entries:
        name, sep, topics = entry.partition("=")
        if not sep or not name.strip() or not topics.split():
            raise ValueError(f"ROVER_WEB_RECORDING_PRESETS: {entry!r} is not NAME=/topic /topic ...")
        presets[name.strip()] = topics.split()
    return presets
