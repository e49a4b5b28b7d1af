"""The ROS graph as plain data, QoS that matches a topic's publishers, and deserializing raw messages."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from .typesupport import message_class

UNKNOWN_NODE = "(node not known yet)"


def _node(endpoint) -> str:
    if endpoint.node_name == "_NODE_NAME_UNKNOWN_":  # endpoint discovered before its node's name
        return UNKNOWN_NODE
    namespace = endpoint.node_namespace.rstrip("/")
    return f"{namespace}/{endpoint.node_name}"


def topic_types(runtime) -> dict[str, list[str]]:
    """Every topic the node has discovered, with its type names."""
    return {name: list(types) for name, types in runtime.node.get_topic_names_and_types()}


def graph_topics(runtime) -> list[dict]:
    """Every discovered topic: name, types, and who publishes and subscribes (this app included)."""
    node = runtime.node
    topics = []
    for name, types in sorted(node.get_topic_names_and_types()):
        publishers = node.get_publishers_info_by_topic(name)
        subscribers = node.get_subscriptions_info_by_topic(name)
        topics.append({
            "name": name,
            "types": list(types),
            "publishers": len(publishers),
            "subscribers": len(subscribers),
            "publisher_nodes": sorted({_node(e) for e in publishers}),
            "subscriber_nodes": sorted({_node(e) for e in subscribers}),
        })
    return topics


def publishers_best_effort(runtime, topic: str) -> bool:
    """True if any publisher on `topic` is best effort (a reliable subscriber would hear nothing)."""
    return any(e.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
               for e in runtime.node.get_publishers_info_by_topic(topic))


def matching_qos(runtime, topic: str, depth: int = 10) -> QoSProfile:
    """QoS that hears every publisher on `topic`, as `ros2 topic echo` chooses it.

    Reliable only if every publisher is reliable; transient local only if every publisher is,
    so a latched map or pose shows at once.
    """
    publishers = runtime.node.get_publishers_info_by_topic(topic)
    reliable = all(e.qos_profile.reliability == ReliabilityPolicy.RELIABLE for e in publishers)
    latched = bool(publishers) and all(e.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
                                       for e in publishers)
    return QoSProfile(depth=depth, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


def qos_summary(profile: QoSProfile) -> str:
    reliability = "reliable" if profile.reliability == ReliabilityPolicy.RELIABLE else "best effort"
    durability = "transient local" if profile.durability == DurabilityPolicy.TRANSIENT_LOCAL else "volatile"
    return f"{reliability}, {durability}"


def deserializer(type_name: str) -> Callable[[bytes], Any]:
    """A function from a serialized message of `type_name` (a raw subscription's bytes) to the message.

    Raises UnknownMessageType (from message_class) if the type cannot be imported.
    """
    return partial(deserialize_message, message_type=message_class(type_name))
