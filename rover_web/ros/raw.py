"""Messages as the CDR bytes ROS sends, for recordings (rover_web/recording): the audit record as a
std_msgs/String, and a node of its own that publishes recorded bytes unchanged (`flask replay`)."""

from __future__ import annotations

from .typesupport import message_class


def string_cdr(text: str) -> bytes:
    """`text` as a serialized std_msgs/msg/String."""
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    return serialize_message(String(data=text))


class RawPublisherNode:
    """An rclpy context and node of its own (not the app's), publishing serialized messages as they are."""

    def __init__(self, node_name: str, domain_id: int | None):
        import rclpy
        from rclpy.context import Context
        from rclpy.signals import SignalHandlerOptions

        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain_id, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node(node_name, context=self.context, start_parameter_services=False)
        self._publishers: list = []

    def publisher(self, type_name: str, topic: str, depth: int = 10, *, latched: bool = False):
        """A publisher whose publish(bytes) sends them as the serialized message; UnknownMessageType
        when the type's Python package is not installed. `latched`: transient local, keeping the
        last `depth` messages for late joiners (what /tf_static's subscribers ask for: they match
        no volatile publisher)."""
        qos = depth
        if latched:
            from .qos import profile

            qos = profile("latched")
            qos.depth = depth
        publisher = self.node.create_publisher(message_class(type_name), topic, qos)
        self._publishers.append(publisher)
        return publisher

    def close(self, ack_timeout_s: float = 2.0) -> None:
        from rclpy.duration import Duration

        for publisher in self._publishers:
            try:  # reliable subscribers get the last messages before the node goes
                publisher.wait_for_all_acked(Duration(seconds=ack_timeout_s))
            except Exception:  # noqa: BLE001 - best effort: leaving is not an error
                pass
        try:
            self.node.destroy_node()
        finally:
            self.context.try_shutdown()
