"""The ROS side of TF: the message type, tf2's QoS for /tf and /tf_static, and whether tf2_msgs is here."""

from __future__ import annotations

from rover_web.ros import qos
from rover_web.ros.typesupport import UnknownMessageType, message_class
from rover_web.web.api_messages import Text, said, text_of

TF_MESSAGE = "tf2_msgs/msg/TFMessage"
HOW_TO_GET = said("source /opt/ros/jazzy/setup.bash before starting rover_web (a ROS install has tf2_msgs), or "
                  "build it into this Python environment with scripts/build_interfaces.sh")

# tf2_ros's TransformListener: /tf reliable, volatile, keep last 100; /tf_static reliable, transient
# local, so a late joiner gets every static transform broadcast before it started (each static
# broadcaster keeps one message with all of its transforms: depth 1 per publisher is enough, tf2 asks
# for more to be safe).
DYNAMIC_QOS = qos.profile("default", depth=100)
STATIC_QOS = qos.profile("latched", depth=100)


def missing() -> Text | None:
    """None when tf2_msgs/msg/TFMessage can be subscribed; otherwise what is missing and how to get it."""
    try:
        message_class(TF_MESSAGE)
    except (UnknownMessageType, ImportError) as exc:
        return said(
            "%(type)s is not available (%(why)s): %(how)s", type=TF_MESSAGE, why=text_of(exc), how=HOW_TO_GET
        )
    return None


def clock_ns(runtime):
    """The node's clock (ROS time: simulated under use_sim_time), which TF stamps are judged against."""
    clock = runtime.node.get_clock()
    return lambda: clock.now().nanoseconds


def publishers(runtime):
    """topic -> the nodes publishing it, as the graph knows them."""
    from rover_web.ros.graph import _node

    def of(topic: str) -> list[str]:
        try:
            return sorted({_node(e) for e in runtime.node.get_publishers_info_by_topic(topic)})
        except Exception:  # noqa: BLE001 - a graph query during shutdown: nothing to show
            return []
    return of
