"""The ROS graph read through a node: plain topic lists, QoS that hears every publisher, raw decoding."""

from types import SimpleNamespace

import pytest
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from rclpy.serialization import serialize_message
from std_msgs.msg import String

from rover_web.ros import graph
from rover_web.ros.typesupport import UnknownMessageType

RELIABLE, BEST_EFFORT = ReliabilityPolicy.RELIABLE, ReliabilityPolicy.BEST_EFFORT
LATCHED, VOLATILE = DurabilityPolicy.TRANSIENT_LOCAL, DurabilityPolicy.VOLATILE


def endpoint(node, reliability=RELIABLE, durability=VOLATILE, namespace="/"):
    return SimpleNamespace(node_name=node, node_namespace=namespace,
                           qos_profile=SimpleNamespace(reliability=reliability, durability=durability))


class FakeNode:
    def __init__(self, topics, publishers=None, subscribers=None):
        self.topics, self.publishers, self.subscribers = topics, publishers or {}, subscribers or {}

    def get_topic_names_and_types(self):
        return list(self.topics.items())

    def get_publishers_info_by_topic(self, name):
        return self.publishers.get(name, [])

    def get_subscriptions_info_by_topic(self, name):
        return self.subscribers.get(name, [])


def runtime(**kwargs):
    return SimpleNamespace(node=FakeNode(**kwargs))


def test_graph_topics_are_sorted_with_their_nodes():
    rt = runtime(topics={"/b": ["std_msgs/msg/String"], "/a": ["std_msgs/msg/Int32", "std_msgs/msg/String"]},
                 publishers={"/a": [endpoint("cam", namespace="/robot/"), endpoint("_NODE_NAME_UNKNOWN_")]},
                 subscribers={"/a": [endpoint("viewer")]})
    topics = graph.graph_topics(rt)
    assert [t["name"] for t in topics] == ["/a", "/b"]
    assert topics[0] == {"name": "/a", "types": ["std_msgs/msg/Int32", "std_msgs/msg/String"], "publishers": 2,
                         "subscribers": 1, "publisher_nodes": [graph.UNKNOWN_NODE, "/robot/cam"],
                         "subscriber_nodes": ["/viewer"]}
    assert graph.topic_types(rt) == {"/b": ["std_msgs/msg/String"],
                                     "/a": ["std_msgs/msg/Int32", "std_msgs/msg/String"]}


def test_one_best_effort_publisher_makes_the_subscription_best_effort():
    rt = runtime(topics={}, publishers={"/cam": [endpoint("a"), endpoint("b", BEST_EFFORT)]})
    assert graph.publishers_best_effort(rt, "/cam")
    assert not graph.publishers_best_effort(rt, "/nobody")
    qos = graph.matching_qos(rt, "/cam")
    assert qos.reliability == BEST_EFFORT and qos.durability == VOLATILE
    assert graph.qos_summary(qos) == "best effort, volatile"


def test_latched_only_when_every_publisher_is():
    rt = runtime(topics={}, publishers={"/map": [endpoint("a", durability=LATCHED)],
                                        "/mixed": [endpoint("a", durability=LATCHED), endpoint("b")]})
    assert graph.qos_summary(graph.matching_qos(rt, "/map")) == "reliable, transient local"
    assert graph.qos_summary(graph.matching_qos(rt, "/mixed")) == "reliable, volatile"
    # No publisher yet: reliable and volatile, as `ros2 topic echo` waits for one.
    assert graph.qos_summary(graph.matching_qos(rt, "/none")) == "reliable, volatile"


def test_deserializer_turns_raw_bytes_back_into_the_message():
    decode = graph.deserializer("std_msgs/msg/String")
    assert decode(serialize_message(String(data="hello"))).data == "hello"
    with pytest.raises(UnknownMessageType):
        graph.deserializer("no_such_msgs/msg/Nothing")
