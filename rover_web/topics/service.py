"""TopicBrowser: the topic list kept fresh on the `topics` channel, and the shared echo subscriptions."""

from __future__ import annotations

import logging
import threading
from collections.abc import Mapping

from rover_web.core.leases import Closed, Full, Leases, ShareUsed
from rover_web.core.state import Rover
from rover_web.ros import graph
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.ros.typesupport import type_name as canonical_type
from rover_web.web.api_messages import explain, text_of
from rover_web.web.validate import InvalidInput, topic_name

from .echo import TopicEcho
from .msgs import dict_decoder

log = logging.getLogger(__name__)


class EchoRefused(Exception):
    """An echo this browser will not open; `code` is the short machine-readable reason."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


class UnknownTopic(EchoRefused):
    """Not in the ROS graph, and no type was given to wait for it."""


class AmbiguousType(EchoRefused):
    """The topic carries several types and the request did not choose one."""


class UnknownType(EchoRefused):
    """The message type cannot be imported in this Python."""


class Unavailable(EchoRefused):
    """Not now: too many echoes are open, or the app is shutting down."""


class CannotSubscribe(EchoRefused):
    """The ROS subscription could not be made."""


class TopicBrowser:
    def __init__(self, rover: Rover):
        self.rover = rover
        config = rover.config
        self.refresh_s = config["ROVER_WEB_TOPICS_REFRESH_S"]
        self.echo_hz = config["ROVER_WEB_TOPICS_ECHO_HZ"]
        self.max_items = config["ROVER_WEB_TOPICS_ECHO_MAX_ITEMS"]
        self.max_viewers = config["ROVER_WEB_SSE_MAX_CLIENTS"]
        self.echoes: Leases[TopicEcho] = Leases(self._open, self._close, config["ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S"],
                                                max_keys=config["ROVER_WEB_TOPICS_ECHO_MAX_SUBSCRIPTIONS"])
        self._viewers = 0
        self._lock = threading.Lock()
        self._published: dict | None = None  # only the refresh loop touches it

    # --- the topic list ---

    def topics(self) -> list[dict]:
        return graph.graph_topics(self.rover.runtime)

    def snapshot(self) -> dict:
        return {"node": self.rover.runtime.node_name, "topics": self.topics()}

    def refresh(self) -> None:
        """Re-read the graph; publish on `topics` only if it changed (an unchanged graph costs browsers nothing)."""
        current = self.snapshot()
        if current != self._published:
            self.rover.hub.publish("topics", current)
            self._published = current

    # --- echo subscriptions ---

    def _open(self, key: tuple[str, str]) -> TopicEcho:
        topic, type_name = key
        echo = TopicEcho(topic, type_name, dict_decoder(type_name, self.max_items), self.echo_hz)
        qos = graph.matching_qos(self.rover.runtime, topic)
        echo.qos = graph.qos_summary(qos)
        echo.subscription = self.rover.runtime.subscribe(type_name, topic, echo.put, qos=qos, track=False, raw=True)
        return echo

    def _close(self, echo: TopicEcho) -> None:
        echo.close()
        if self.rover.runtime.running:
            self.rover.runtime.destroy(echo.subscription)

    def resolve(self, args: Mapping[str, str]) -> tuple[str, str]:
        """(topic, type) an echo request asks for; InvalidInput or EchoRefused if it cannot be echoed."""
        topic = topic_name(args.get("topic"))
        known = graph.topic_types(self.rover.runtime).get(topic) or []
        type_name = args.get("type") or None
        if type_name is None:
            if not known:
                raise UnknownTopic(explain("no topic %(topic)s in the ROS graph; give type=pkg/msg/Name to wait "
                                           "for it",
                                           topic=topic),
                                   "unknown_topic")
            if len(known) > 1:
                raise AmbiguousType(explain("%(topic)s carries several types (%(known)s); choose one with type=",
                                            topic=topic, known=', '.join(known)),
                                    "ambiguous_type")
            type_name = known[0]
        try:
            cls = message_class(type_name)
        except UnknownMessageType as exc:
            raise UnknownType(
                explain("cannot show %(topic)s: %(why)s", topic=topic, why=text_of(exc)), "unknown_type"
            ) from None
        type_name = canonical_type(cls)
        if known and type_name not in known:
            raise InvalidInput("%(topic)s carries %(known)s, not %(type_name)s", "type_mismatch",
                               topic=topic, known=', '.join(known), type_name=type_name)
        return topic, type_name

    def acquire(self, key: tuple[str, str], client: str | None = None) -> TopicEcho:
        with self._lock:
            if self._viewers >= self.max_viewers:
                raise Unavailable(
                    explain("%(viewers)s topic echoes are open already", viewers=self._viewers), "too_many_streams"
                )
            self._viewers += 1
        try:
            return self.echoes.acquire(key, client, self._share(client))
        except Closed:
            self._viewer_left()
            raise Unavailable(explain("the server is shutting down"), "shutting_down") from None
        except ShareUsed as exc:
            self._viewer_left()
            raise Unavailable(
                explain(
                    "%(why)s different topic echoes (ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT); close one first",
                    why=text_of(exc),
                ),
                "too_many_subscriptions",
            ) from None
        except Full:
            self._viewer_left()
            raise Unavailable(
                explain(
                    "%(count)s different topics are being echoed already "
                    "(ROVER_WEB_TOPICS_ECHO_MAX_SUBSCRIPTIONS); try again when one closes",
                    count=len(self.echoes),
                ),
                "too_many_subscriptions",
            ) from None
        except Exception as exc:
            self._viewer_left()
            log.exception("cannot subscribe to %s", key[0])
            raise CannotSubscribe(
                explain("cannot subscribe to %(key)s: %(why)s", key=key[0], why=text_of(exc)), "cannot_subscribe"
            ) from None

    def release(self, key: tuple[str, str], client: str | None = None) -> None:
        self.echoes.release(key, client)
        self._viewer_left()

    def _share(self, client: str | None) -> int | None:
        return None if client is None else self.rover.config["ROVER_WEB_SUBSCRIPTIONS_PER_CLIENT"]

    def _viewer_left(self) -> None:
        with self._lock:
            self._viewers -= 1

    def close(self) -> None:
        self.echoes.close_all()
