"""CameraStreams: the frame producers of one app, shared by viewers, with its viewer limit and encoding settings."""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping

from rover_web.core.leases import Closed, Full, Leases, ShareUsed
from rover_web.core.rate_limit import RateLimit
from rover_web.core.state import Rover
from rover_web.ros.graph import publishers_best_effort, topic_types
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.web.api_messages import explain, text_of
from rover_web.web.validate import InvalidInput

from . import imaging
from . import msgs as camera_msgs
from .acks import AckedStream, AckedStreams
from .params import parse_stream_args
from .rate import Budget, Meter, ViewerRate
from .stream import FrameProducer, FrameSource, SourceKey, StreamKey, source_key

log = logging.getLogger(__name__)


class StreamRefused(Exception):
    """A stream this service will not open; `code` is the short machine-readable reason."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


class UnknownTopic(StreamRefused):
    """Not in the ROS graph, and no message type was given to wait for it."""


class Unavailable(StreamRefused):
    """Not now: too many viewers, or the app is shutting down."""


class CannotSubscribe(StreamRefused):
    """The ROS subscription could not be made."""


class Client:
    """One /stream viewer: what it asked for, the output it gets now, and what it is sent."""

    def __init__(self, id: int, label: str | None, key: StreamKey, rate: ViewerRate | None):
        self.id, self.label, self.asked, self.key, self.rate = id, label, key, key, rate
        self.owner: str | None = None
        self.meter = rate.meter if rate is not None else Meter()
        self.acks: AckedStream | None = None  # an acknowledging page's counts (GET /stream?ack=1)

    def report(self) -> dict:
        report = self.rate.report() if self.rate is not None else self.meter.report()
        acks = self.acks.report() if self.acks is not None else {}
        return {"id": self.id, "viewer": self.label, "topic": self.asked.topic, "adapt": self.rate is not None,
                "acked": self.acks is not None,
                "asked": {"width": self.asked.width, "height": self.asked.height, "quality": self.asked.quality},
                **report, **acks}


class CameraStreams:
    """The producers of one app, its viewer limit and the encoding settings."""

    def __init__(self, rover: Rover):
        self.rover = rover
        config = rover.config
        self.max_dimension = config["ROVER_WEB_CAMERA_MAX_DIMENSION"]
        self.default_quality = config["ROVER_WEB_CAMERA_QUALITY"]
        self.max_viewers = config["ROVER_WEB_CAMERA_MAX_VIEWERS"]
        self.snapshot_timeout_s = config["ROVER_WEB_CAMERA_SNAPSHOT_TIMEOUT_S"]
        self.max_output_pixels = config["ROVER_WEB_CAMERA_MAX_OUTPUT_PIXELS"]
        self.snapshots = RateLimit(config["ROVER_WEB_CAMERA_SNAPSHOTS_PER_MIN"], 60.0)
        self.producers: Leases[FrameProducer] = Leases(self._open, self._close,
                                                       config["ROVER_WEB_CAMERA_IDLE_TIMEOUT_S"],
                                                       max_keys=config["ROVER_WEB_CAMERA_MAX_PRODUCERS"])
        self.adapt = config["ROVER_WEB_CAMERA_ADAPT"]
        self.viewer_max_bps = config["ROVER_WEB_CAMERA_VIEWER_MAX_KBPS"] * 1000 / 8 or None
        self.budget = Budget(config["ROVER_WEB_CAMERA_TOTAL_MAX_KBPS"] * 1000 / 8 or None)
        self._sources: dict[SourceKey, FrameSource] = {}
        self._source_lock = threading.Lock()
        self._clients: dict[int, Client] = {}
        self.acked = AckedStreams()  # the streams whose pages acknowledge, by their unguessable id
        self._next_client = 0
        self._viewers = 0
        self._lock = threading.Lock()

    # --- producers ---

    def _open(self, key: StreamKey) -> FrameProducer:
        """Called under the producers' lock, so two outputs cannot both make a subscription."""
        producer = FrameProducer(key, lambda raw: self._encode(key, raw))
        skey = source_key(key)
        with self._source_lock:
            source = self._sources.get(skey)
            if source is None:
                source = FrameSource(skey)
                read = camera_msgs.frame_reader(key.msg_type)
                source.subscription = self.rover.runtime.subscribe(
                    key.msg_type, key.topic, lambda msg: source.put(read(msg)), qos=key.qos, track=False)
                self._sources[skey] = source
            source.attach(producer)
        producer.subscription = source.subscription
        return producer

    def _close(self, producer: FrameProducer) -> None:
        producer.close()
        skey = source_key(producer.key)
        with self._source_lock:
            source = self._sources.get(skey)
            if source is None or source.detach(producer):
                return
            del self._sources[skey]
        if self.rover.runtime.running:  # after runtime.stop the node and its subscriptions are gone
            self.rover.runtime.destroy(source.subscription)

    def _encode(self, key: StreamKey, raw) -> imaging.Jpeg:
        try:
            return imaging.encode_frame(raw, key.quality, key.width, key.height, self.max_output_pixels)
        except Exception:  # a bug, not bad data: keep the stream alive and say where to look
            log.exception("encoding a frame from %s failed", key.topic)
            return imaging.error_frame("the server could not encode this frame; see its log", "internal_error",
                                       key.width, key.height, max_pixels=self.max_output_pixels)

    # --- requests ---

    def key_for(self, args: Mapping[str, str]) -> StreamKey:
        """The stream a request asks for, with type and QoS resolved from the ROS graph.

        InvalidInput for a bad query, UnknownTopic for a topic the graph does not know (and no type given).
        """
        parsed = parse_stream_args(args, max_dimension=self.max_dimension, default_quality=self.default_quality,
                                   max_pixels=self.max_output_pixels)
        topic = parsed["topic"]
        runtime = self.rover.runtime
        known = topic_types(runtime).get(topic)
        if parsed["msg_type"]:
            msg_type = _image_type(parsed["msg_type"])
            if known and msg_type not in known:
                raise InvalidInput("%(topic)s carries %(known)s, not %(msg_type)s", "type_mismatch",
                                   topic=topic, known=', '.join(known), msg_type=msg_type)
        else:
            if not known:
                raise UnknownTopic(explain("no topic %(topic)s in the ROS graph (GET /api/topics lists them); to "
                                           "wait for a camera that is not up yet, add "
                                           "msg_type=sensor_msgs/msg/Image or CompressedImage",
                                           topic=topic),
                                   "unknown_topic")
            images = [t for t in known if t in camera_msgs.IMAGE_TYPES]
            if not images:
                raise InvalidInput("%(topic)s carries %(known)s; streams need sensor_msgs/msg/Image or "
                                   "sensor_msgs/msg/CompressedImage", "not_an_image_topic",
                                   topic=topic, known=', '.join(known))
            msg_type = images[0]
        qos = parsed["qos"]
        if qos is None:  # like `ros2 topic echo`: best effort if any publisher is, or nothing would arrive
            qos = "sensor_data" if publishers_best_effort(runtime, topic) else "default"
        return StreamKey(topic, msg_type, qos, parsed["width"], parsed["height"], parsed["quality"])

    def acquire(self, key: StreamKey, client: str | None = None) -> FrameProducer:
        with self._lock:
            if self._viewers >= self.max_viewers:
                raise Unavailable(explain("%(viewers)s camera viewers are connected already "
                                          "(ROVER_WEB_CAMERA_MAX_VIEWERS)",
                                          viewers=self._viewers), "too_many_viewers")
            self._viewers += 1
        try:
            return self.producers.acquire(key, client, self._share(client))
        except Closed:
            self._viewer_left()
            raise Unavailable(explain("the server is shutting down"), "shutting_down") from None
        except ShareUsed as exc:
            self._viewer_left()
            raise Unavailable(
                explain(
                    "%(why)s different camera encodings (ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT); close one first",
                    why=text_of(exc),
                ),
                "too_many_producers",
            ) from None
        except Full:
            self._viewer_left()
            raise Unavailable(
                explain(
                    "%(count)s different camera streams are being encoded already "
                    "(ROVER_WEB_CAMERA_MAX_PRODUCERS); view one of them, or try again when one "
                    "ends",
                    count=len(self.producers),
                ),
                "too_many_producers",
            ) from None
        except Exception as exc:
            self._viewer_left()
            log.exception("cannot subscribe to %s", key.topic)
            raise CannotSubscribe(
                explain("cannot subscribe to %(topic)s: %(why)s", topic=key.topic, why=text_of(exc)), "cannot_subscribe"
            ) from None

    def release(self, key: StreamKey, client: str | None = None) -> None:
        self.producers.release(key, client)
        self._viewer_left()

    def _share(self, client: str | None) -> int | None:
        return None if client is None else self.rover.config["ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT"]

    def switch(self, old: StreamKey, new: StreamKey, owner: str | None = None) -> FrameProducer:
        """A viewer moves to another output of its topic (adaptation); Full or Closed leaves it where it was.
        For a moment it holds both: its share of encodings allows the one more."""
        share = self._share(owner)
        producer = self.producers.acquire(new, owner, None if share is None else share + 1)
        self.producers.release(old, owner)
        return producer

    # --- viewers, for the camera card and the rate control ---

    def client(self, key: StreamKey, label: str | None, owner: str | None = None, *,
               acks_from: str | None | bool = False) -> Client:
        """A viewer's record: its rate control (or only a meter with adaptation off) and what it watches.
        `acks_from`: the signed-in name (or None) of a page that will acknowledge what it receives;
        False for one that will not. Only an adaptive stream uses acknowledgements."""
        rate = ViewerRate(key.quality, max_bps=self.viewer_max_bps, budget=self.budget) if self.adapt else None
        with self._lock:
            self._next_client += 1
            client = Client(self._next_client, label, key, rate)
            client.owner = owner  # whose share of the encodings it holds (web/streams.py)
            self._clients[client.id] = client
        if rate is not None and acks_from is not False:
            client.acks = self.acked.open(acks_from)
        return client

    def client_left(self, client: Client) -> None:
        with self._lock:
            self._clients.pop(client.id, None)
        if client.acks is not None:
            self.acked.close(client.acks)  # its acks are 404 from now on
        if client.rate is not None:
            client.rate.close()

    def clients(self, label: str | None = None) -> list[dict]:
        with self._lock:
            clients = list(self._clients.values())
        return [c.report() for c in clients if label is None or c.label == label]

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

    def panel(self) -> dict:
        """What the dashboard's camera panel shows: the configured topic first, even before it exists."""
        topic = self.rover.config["ROVER_WEB_CAMERA_TOPIC"]
        topics = self.image_topics()
        if topic not in [t["name"] for t in topics]:
            topics.insert(0, {"name": topic, "type": None})
        return {"topic": topic, "image_topics": topics}

    def close(self) -> None:
        self.producers.close_all()


def _image_type(name: str) -> str:
    canonical = camera_msgs.image_type(name)
    if canonical:
        return canonical
    try:
        message_class(name)
    except UnknownMessageType as exc:
        raise InvalidInput(text_of(exc), "unknown_type") from None
    raise InvalidInput(
        "%(name)s is not an image type; use sensor_msgs/msg/Image or sensor_msgs/msg/CompressedImage",
        "not_an_image_type",
        name=name[:80],
    )
