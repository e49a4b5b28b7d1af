"""The topic browser: GET /topics, GET /api/topics, the `topics` channel and a live echo of any topic.

`ros2 topic list -v`, `ros2 topic echo`, `hz` and `bw` in the app's own node. The topic list is
re-read from the ROS graph every ROVER_WEB_TOPICS_REFRESH_S and published on the `topics`
channel when it changes. GET /api/topics/echo?topic=... is an SSE stream of one topic's messages
(at most ROVER_WEB_TOPICS_ECHO_HZ a second) with its measured rate and bandwidth; viewers of the
same topic share one raw subscription, removed ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S after the
last viewer leaves.
"""

from __future__ import annotations

import logging
import threading
import time

from flask import Blueprint, Response, current_app, jsonify, render_template, request

from rover_web.core.state import Rover
from rover_web.events.hub import encode
from rover_web.web.http import ApiError
from rover_web.core.leases import Closed, Leases
from . import msgs as topics_msgs
from rover_web.camera.msgs import IMAGE_TYPES
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.ros.typesupport import type_name as canonical_type
from rover_web.web.connection import peer_gone
from .echo import EchoClosed, TopicEcho
from rover_web.web.validate import InvalidInput, topic_name

log = logging.getLogger(__name__)

bp = Blueprint("topics", __name__)

STATS_PERIOD_S = 1.0  # rate and bandwidth go out this often even when no message is shown
LIVENESS_CHECK_S = 1.0


class TopicBrowser:
    def __init__(self, rover: Rover):
        self.rover = rover
        config = rover.config
        self.refresh_s = config["ROVER_WEB_TOPICS_REFRESH_S"]
        self.echo_hz = config["ROVER_WEB_TOPICS_ECHO_HZ"]
        self.max_items = config["ROVER_WEB_TOPICS_ECHO_MAX_ITEMS"]
        self.max_viewers = config["ROVER_WEB_SSE_MAX_CLIENTS"]
        self.echoes: Leases[TopicEcho] = Leases(self._open, self._close, config["ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S"])
        self._viewers = 0
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None

    # --- the topic list ---

    def topics(self) -> list[dict]:
        return topics_msgs.graph_topics(self.rover.runtime)

    def snapshot(self) -> dict:
        return {"node": self.rover.runtime.node_name, "topics": self.topics()}

    def start(self) -> None:
        def run() -> None:
            last = None
            while True:
                try:
                    current = self.snapshot()
                    if current != last:  # an unchanged graph costs the browsers nothing
                        self.rover.hub.publish("topics", current)
                        last = current
                except Exception:
                    if self.rover.stopping.is_set():
                        return
                    log.exception("reading the ROS graph failed")
                if self.rover.stopping.wait(self.refresh_s):
                    return

        self._thread = threading.Thread(target=run, name="topics-refresh", daemon=True)
        self._thread.start()
        self.echoes.start_reaper("topics-echo-reaper")

    # --- echo subscriptions ---

    def _open(self, key: tuple[str, str]) -> TopicEcho:
        topic, type_name = key
        echo = TopicEcho(topic, type_name, topics_msgs.dict_decoder(type_name, self.max_items), self.echo_hz)
        qos = topics_msgs.matching_qos(self.rover.runtime, topic)
        echo.qos = topics_msgs.qos_summary(qos)
        echo.subscription = self.rover.runtime.subscribe(type_name, topic, echo.put, qos=qos, track=False, raw=True)
        return echo

    def _close(self, echo: TopicEcho) -> None:
        echo.close()
        if self.rover.runtime.running:
            self.rover.runtime.destroy(echo.subscription)

    def resolve(self, args) -> tuple[str, str]:
        """(topic, type) an echo request asks for; ApiError for bad names and unimportable types."""
        try:
            topic = topic_name(args.get("topic"))
        except InvalidInput as exc:
            raise ApiError(400, exc.code, str(exc)) from None
        known = topics_msgs.topic_types(self.rover.runtime).get(topic) or []
        type_name = args.get("type") or None
        if type_name is None:
            if not known:
                raise ApiError(404, "unknown_topic", f"no topic {topic} in the ROS graph; give type=pkg/msg/Name "
                                                     f"to wait for it")
            if len(known) > 1:
                raise ApiError(409, "ambiguous_type", f"{topic} carries several types ({', '.join(known)}); "
                                                      f"choose one with type=")
            type_name = known[0]
        try:
            cls = message_class(type_name)
        except UnknownMessageType as exc:
            raise ApiError(422, "unknown_type", f"cannot show {topic}: {exc}") from None
        type_name = canonical_type(cls)
        if known and type_name not in known:
            raise ApiError(400, "type_mismatch", f"{topic} carries {', '.join(known)}, not {type_name}")
        return topic, type_name

    def acquire(self, key: tuple[str, str]) -> TopicEcho:
        with self._lock:
            if self._viewers >= self.max_viewers:
                raise ApiError(503, "too_many_streams", f"{self._viewers} topic echoes are open already")
            self._viewers += 1
        try:
            return self.echoes.acquire(key)
        except Closed:
            self._viewer_left()
            raise ApiError(503, "shutting_down", "the server is shutting down") from None
        except Exception as exc:
            self._viewer_left()
            log.exception("cannot subscribe to %s", key[0])
            raise ApiError(400, "cannot_subscribe", f"cannot subscribe to {key[0]}: {exc}") from None

    def release(self, key: tuple[str, str]) -> None:
        self.echoes.release(key)
        self._viewer_left()

    def _viewer_left(self) -> None:
        with self._lock:
            self._viewers -= 1

    def close(self) -> None:
        self.echoes.close_all()
        if self._thread is not None:
            self._thread.join(2.0)


def current_browser() -> TopicBrowser:
    return current_app.extensions["rover_web_topics"]


def echo_event(echo: TopicEcho, kind: str, sample=None) -> bytes:
    """An SSE frame without an id: a reconnecting browser wants the newest message, not a replay."""
    data = {"topic": echo.topic, "type": echo.type_name, "qos": echo.qos, "max_hz": round(1 / echo.min_interval_s, 3),
            "stats": echo.meter.snapshot()}
    if sample is not None:
        data["seq"], data["msg"], data["error"] = sample
    return f"event: {kind}\ndata: {encode(data)}\n\n".encode()


@bp.get("/topics")
def topics_page():
    browser = current_browser()
    selected = request.args.get("topic", "")
    try:
        selected = topic_name(selected) if selected else ""
    except InvalidInput:
        selected = ""
    return render_template("topics.html", graph=browser.snapshot(), selected=selected,
                           image_types=list(IMAGE_TYPES), echo_hz=browser.echo_hz)


@bp.get("/api/topics")
def api_topics():
    return jsonify(current_browser().snapshot())


@bp.get("/api/topics/echo")
def api_echo():
    browser = current_browser()
    rover = browser.rover
    key = browser.resolve(request.args)
    echo = browser.acquire(key)
    released = threading.Event()

    def release() -> None:
        if not released.is_set():
            released.set()
            browser.release(key)

    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    keepalive_s = rover.config["ROVER_WEB_SSE_KEEPALIVE_S"]
    retry = f"retry: {rover.config['ROVER_WEB_SSE_RETRY_MS']}\n\n".encode()
    stopping = rover.stopping

    def stream():
        yield retry + echo_event(echo, "stats")
        sent_seq = 0
        next_send = 0.0
        last_write = time.monotonic()
        while not stopping.is_set():
            try:
                newer = echo.wait_newer(sent_seq, min(STATS_PERIOD_S, keepalive_s))
            except EchoClosed:
                return
            now = time.monotonic()
            if newer:
                if now < next_send and stopping.wait(next_send - now):
                    return
                sample = echo.sample()
                if sample[0] > sent_seq:
                    yield echo_event(echo, "echo", sample)
                    sent_seq = sample[0]
                    last_write = now = time.monotonic()
                    next_send = now + echo.min_interval_s
                    continue
                # Another viewer of this topic decoded a moment ago; the next decode is due soon.
                next_send = max(next_send, echo.next_decode_at)
            if now - last_write >= STATS_PERIOD_S:
                yield echo_event(echo, "stats")
                last_write = now
            elif peer_gone(sock):
                return

    response = Response(stream(), mimetype="text/event-stream",
                        headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})
    response.call_on_close(release)
    return response


def init_app(app, rover: Rover) -> None:
    browser = TopicBrowser(rover)
    app.extensions["rover_web_topics"] = browser
    rover.hub.register("topics")
    app.register_blueprint(bp)
    rover.add_nav("Topics", "/topics")
    browser.start()
    rover.on_shutdown(browser.close)
