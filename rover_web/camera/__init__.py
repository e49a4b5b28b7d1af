"""Camera streaming in the app's own process: GET /stream (MJPEG), GET /snapshot, the camera panel.

Replaces web_video_server. One FrameProducer (one ROS subscription) per distinct
(topic, type, QoS, width, height, quality): made by the first viewer, shared by the others and
destroyed ROVER_WEB_CAMERA_IDLE_TIMEOUT_S after the last one leaves. Frames are encoded in
request threads, once each (see camera_stream.py), never on the ROS executor.
"""

from __future__ import annotations

import logging
import threading
from typing import Mapping

from flask import Blueprint, Response, current_app, jsonify, request

from . import imaging
from .stream import FrameProducer, StreamClosed, StreamKey
from rover_web.core.state import Rover
from rover_web.web.http import ApiError
from rover_web.core.leases import Closed, Leases
from . import msgs as camera_msgs
from rover_web.topics.msgs import publishers_best_effort, topic_types
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.web.connection import peer_gone
from rover_web.web.validate import InvalidInput, topic_name

log = logging.getLogger(__name__)

bp = Blueprint("camera", __name__)

BOUNDARY = "frame"
QOS_PROFILES = ("default", "sensor_data")
# web_video_server's `type` is the stream format; MJPEG is the one this server makes.
STREAM_TYPES = ("mjpeg",)
# How often a stream with no new frame checks that its browser is still there.
LIVENESS_CHECK_S = 1.0
NO_CACHE = {"Cache-Control": "no-cache, no-store, must-revalidate", "Pragma": "no-cache", "Expires": "0"}


def _int_arg(args: Mapping[str, str], name: str, low: int, high: int, *, original_ok: bool = False) -> int | None:
    text = args.get(name)
    if text is None or text.strip() == "":
        return None
    text = text.strip()
    try:
        value = int(text, 10)
    except ValueError:
        raise InvalidInput(f"'{name}' must be a whole number, got {text[:20]!r}", "bad_type") from None
    if original_ok and value in (0, -1):  # web_video_server's "keep the camera's size"
        return None
    if not low <= value <= high:
        raise InvalidInput(f"'{name}' must be between {low} and {high}, got {value}", "out_of_range")
    return value


def parse_stream_args(args: Mapping[str, str], *, max_dimension: int, default_quality: int) -> dict:
    """Check a /stream or /snapshot query; the message type and QoS may still be left to the graph."""
    topic = topic_name(args.get("topic"))
    width = _int_arg(args, "width", 1, max_dimension, original_ok=True)
    height = _int_arg(args, "height", 1, max_dimension, original_ok=True)
    quality = _int_arg(args, "quality", 1, 100)
    qos = args.get("qos_profile") or None
    if qos is not None and qos not in QOS_PROFILES:
        raise InvalidInput(f"'qos_profile' must be one of {', '.join(QOS_PROFILES)}; got {qos[:40]!r}", "bad_value")
    stream_type = args.get("type")
    msg_type = args.get("msg_type") or None
    if stream_type and stream_type not in STREAM_TYPES:
        if "/" not in stream_type:
            raise InvalidInput(f"stream type {stream_type[:40]!r} is not supported; this server streams mjpeg",
                               "unsupported_stream_type")
        msg_type = msg_type or stream_type  # type=sensor_msgs/msg/Image works too
    return {"topic": topic, "width": width, "height": height,
            "quality": default_quality if quality is None else quality, "qos": qos, "msg_type": msg_type}


def multipart_part(jpeg: imaging.Jpeg) -> bytes:
    """One JPEG and the boundary after it, so a browser shows the frame as soon as it arrives."""
    head = (f"Content-Type: image/jpeg\r\nContent-Length: {len(jpeg.data)}\r\n"
            f"X-Timestamp: {jpeg.stamp:.9f}\r\n\r\n").encode()
    return head + jpeg.data + f"\r\n--{BOUNDARY}\r\n".encode()


class CameraStreams:
    """The producers of one app, its viewer limit and the encoding settings."""

    def __init__(self, rover: Rover):
        self.rover = rover
        config = rover.config
        self.max_dimension = config["ROVER_WEB_CAMERA_MAX_DIMENSION"]
        self.default_quality = config["ROVER_WEB_CAMERA_QUALITY"]
        self.max_viewers = config["ROVER_WEB_CAMERA_MAX_VIEWERS"]
        self.snapshot_timeout_s = config["ROVER_WEB_CAMERA_SNAPSHOT_TIMEOUT_S"]
        self.producers: Leases[FrameProducer] = Leases(self._open, self._close,
                                                       config["ROVER_WEB_CAMERA_IDLE_TIMEOUT_S"])
        self._viewers = 0
        self._lock = threading.Lock()

    # --- producers ---

    def _open(self, key: StreamKey) -> FrameProducer:
        producer = FrameProducer(key, lambda raw: self._encode(key, raw))
        read = camera_msgs.frame_reader(key.msg_type)
        producer.subscription = self.rover.runtime.subscribe(
            key.msg_type, key.topic, lambda msg: producer.put(read(msg)), qos=key.qos, track=False)
        return producer

    def _close(self, producer: FrameProducer) -> None:
        producer.close()
        if self.rover.runtime.running:  # after runtime.stop the node and its subscriptions are gone
            self.rover.runtime.destroy(producer.subscription)

    @staticmethod
    def _encode(key: StreamKey, raw) -> imaging.Jpeg:
        try:
            return imaging.encode_frame(raw, key.quality, key.width, key.height)
        except Exception:  # a bug, not bad data: keep the stream alive and say where to look
            log.exception("encoding a frame from %s failed", key.topic)
            return imaging.error_frame("the server could not encode this frame; see its log", "internal_error",
                                       key.width, key.height)

    # --- requests ---

    def key_for(self, args: Mapping[str, str]) -> StreamKey:
        """The stream a request asks for, with type and QoS resolved from the ROS graph; ApiError if bad."""
        try:
            parsed = parse_stream_args(args, max_dimension=self.max_dimension, default_quality=self.default_quality)
        except InvalidInput as exc:
            raise ApiError(400, exc.code, str(exc)) from None
        topic = parsed["topic"]
        runtime = self.rover.runtime
        known = topic_types(runtime).get(topic)
        if parsed["msg_type"]:
            msg_type = _image_type(parsed["msg_type"])
            if known and msg_type not in known:
                raise ApiError(400, "type_mismatch", f"{topic} carries {', '.join(known)}, not {msg_type}")
        else:
            if not known:
                raise ApiError(404, "unknown_topic",
                               f"no topic {topic} in the ROS graph (GET /api/topics lists them); to wait for a "
                               f"camera that is not up yet, add msg_type=sensor_msgs/msg/Image or CompressedImage")
            images = [t for t in known if t in camera_msgs.IMAGE_TYPES]
            if not images:
                raise ApiError(400, "not_an_image_topic",
                               f"{topic} carries {', '.join(known)}; streams need sensor_msgs/msg/Image "
                               f"or sensor_msgs/msg/CompressedImage")
            msg_type = images[0]
        qos = parsed["qos"]
        if qos is None:  # like `ros2 topic echo`: best effort if any publisher is, or nothing would arrive
            qos = "sensor_data" if publishers_best_effort(runtime, topic) else "default"
        return StreamKey(topic, msg_type, qos, parsed["width"], parsed["height"], parsed["quality"])

    def acquire(self, key: StreamKey) -> FrameProducer:
        with self._lock:
            if self._viewers >= self.max_viewers:
                raise ApiError(503, "too_many_viewers",
                               f"{self._viewers} camera viewers are connected already (ROVER_WEB_CAMERA_MAX_VIEWERS)")
            self._viewers += 1
        try:
            return self.producers.acquire(key)
        except Closed:
            self._viewer_left()
            raise ApiError(503, "shutting_down", "the server is shutting down") from None
        except Exception as exc:
            self._viewer_left()
            log.exception("cannot subscribe to %s", key.topic)
            raise ApiError(400, "cannot_subscribe", f"cannot subscribe to {key.topic}: {exc}") from None

    def release(self, key: StreamKey) -> None:
        self.producers.release(key)
        self._viewer_left()

    def _viewer_left(self) -> None:
        with self._lock:
            self._viewers -= 1

    @property
    def viewers(self) -> int:
        with self._lock:
            return self._viewers

    def describe(self) -> list[dict]:
        out = []
        for key, producer, users in self.producers.items():
            out.append({"topic": key.topic, "msg_type": key.msg_type, "qos_profile": key.qos,
                        "width": key.width, "height": key.height, "quality": key.quality,
                        "viewers": users, **producer.stats()})
        return out

    def image_topics(self) -> list[dict]:
        try:
            types = topic_types(self.rover.runtime)
        except Exception:  # the node is gone (shutdown): an empty list, not a broken page
            return []
        return [{"name": name, "type": next(t for t in ts if t in camera_msgs.IMAGE_TYPES)}
                for name, ts in sorted(types.items()) if any(t in camera_msgs.IMAGE_TYPES for t in ts)]

    def close(self) -> None:
        self.producers.close_all()


def _image_type(name: str) -> str:
    canonical = camera_msgs.image_type(name)
    if canonical:
        return canonical
    try:
        message_class(name)
    except UnknownMessageType as exc:
        raise ApiError(400, "unknown_type", str(exc)) from None
    raise ApiError(400, "not_an_image_type",
                   f"{name[:80]} is not an image type; use sensor_msgs/msg/Image or sensor_msgs/msg/CompressedImage")


def current_streams() -> CameraStreams:
    return current_app.extensions["rover_web_camera"]


@bp.get("/stream")
def stream():
    streams = current_streams()
    rover = streams.rover
    key = streams.key_for(request.args)
    producer = streams.acquire(key)
    released = threading.Event()

    def release() -> None:
        if not released.is_set():
            released.set()
            streams.release(key)

    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    stopping = rover.stopping

    def frames():
        yield f"--{BOUNDARY}\r\n".encode()  # headers go out now, not at the first frame
        seq = 0
        while not stopping.is_set():
            try:
                got = producer.next_frame(seq, LIVENESS_CHECK_S)
            except StreamClosed:
                return
            if got is None:
                if peer_gone(sock):
                    return
                continue
            seq, jpeg = got
            yield multipart_part(jpeg)

    response = Response(frames(), mimetype=f"multipart/x-mixed-replace; boundary={BOUNDARY}",
                        headers={**NO_CACHE, "X-Accel-Buffering": "no"})
    # WSGI servers call close() however the response ends (done, browser gone, error), even if
    # the generator never started, so the viewer is always released exactly once.
    response.call_on_close(release)
    return response


@bp.get("/snapshot")
def snapshot():
    streams = current_streams()
    key = streams.key_for(request.args)
    producer = streams.acquire(key)
    try:
        try:
            got = producer.next_frame(0, streams.snapshot_timeout_s)
        except StreamClosed:
            raise ApiError(503, "shutting_down", "the server is shutting down") from None
    finally:
        streams.release(key)
    if got is None:
        raise ApiError(504, "no_frame", f"no image arrived on {key.topic} within {streams.snapshot_timeout_s:g} s "
                                        f"(QoS {key.qos}); is the camera publishing?")
    jpeg = got[1]
    if jpeg.error is not None:
        status = 415 if jpeg.error_code == "unsupported_encoding" else 422
        raise ApiError(status, jpeg.error_code or "bad_image", jpeg.error)
    return Response(jpeg.data, mimetype="image/jpeg",
                    headers={**NO_CACHE, "X-Timestamp": f"{jpeg.stamp:.9f}"})


@bp.get("/api/camera/streams")
def streams_status():
    streams = current_streams()
    return jsonify(viewers=streams.viewers, streams=streams.describe())


def init_app(app, rover: Rover) -> None:
    streams = CameraStreams(rover)
    app.extensions["rover_web_camera"] = streams
    streams.producers.start_reaper("camera-reaper")
    rover.on_shutdown(streams.close)
    app.register_blueprint(bp)

    def camera_panel() -> dict:
        topic = rover.config["ROVER_WEB_CAMERA_TOPIC"]
        topics = streams.image_topics()
        if topic not in [t["name"] for t in topics]:
            topics.insert(0, {"name": topic, "type": None})
        return {"topic": topic, "image_topics": topics}

    app.jinja_env.globals["camera_panel"] = camera_panel
    rover.add_panel(20, "panels/camera.html", "Camera")
