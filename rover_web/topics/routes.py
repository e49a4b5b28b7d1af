"""GET /topics (the page), GET /api/topics (the graph) and GET /api/topics/echo (one topic as SSE)."""

from __future__ import annotations

import time

from flask import Blueprint, Response, jsonify, render_template, request

from rover_web.camera.msgs import IMAGE_TYPES
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.connection import peer_gone
from rover_web.web.http import error_response
from rover_web.web.streams import once, opening
from rover_web.web.validate import InvalidInput, topic_name

from .echo import EchoClosed, echo_event
from .service import AmbiguousType, CannotSubscribe, EchoRefused, TopicBrowser, Unavailable, UnknownTopic, UnknownType

bp = Blueprint("topics", __name__)

STATS_PERIOD_S = 1.0  # rate and bandwidth go out this often even when no message is shown

STATUS = {UnknownTopic: 404, AmbiguousType: 409, UnknownType: 422, Unavailable: 503, CannotSubscribe: 400}


@bp.errorhandler(InvalidInput)
def invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


@bp.errorhandler(EchoRefused)
def echo_refused(exc: EchoRefused):
    return error_response(STATUS[type(exc)], exc.code, text_of(exc))


@bp.get("/topics")
def topics_page():
    browser = current_feature(TopicBrowser)
    selected = request.args.get("topic", "")
    try:
        selected = topic_name(selected) if selected else ""
    except InvalidInput:
        selected = ""
    return render_template("topics.html", graph=browser.snapshot(), selected=selected,
                           image_types=list(IMAGE_TYPES), echo_hz=browser.echo_hz)


@bp.get("/api/topics")
def api_topics():
    return jsonify(current_feature(TopicBrowser).snapshot())


@bp.get("/api/topics/echo")
def api_echo():
    browser = current_feature(TopicBrowser)
    rover = browser.rover
    with opening("topic_echo") as slot:
        key = browser.resolve(request.args)
        echo = browser.acquire(key, slot.client)
    release = once(lambda: browser.release(key, slot.client), slot.release)

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
