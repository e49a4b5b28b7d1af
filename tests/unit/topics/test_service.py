"""The topic list goes out on the `topics` channel when the graph changes, and only then."""

from types import SimpleNamespace

from rover_web.topics.service import TopicBrowser

CONFIG = {"ROVER_WEB_TOPICS_REFRESH_S": 2.0, "ROVER_WEB_TOPICS_ECHO_HZ": 4.0, "ROVER_WEB_TOPICS_ECHO_MAX_ITEMS": 32,
          "ROVER_WEB_SSE_MAX_CLIENTS": 8, "ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S": 5.0,
          "ROVER_WEB_TOPICS_ECHO_MAX_SUBSCRIPTIONS": 16}


class FakeNode:
    def __init__(self):
        self.topics = {"/odom": ["nav_msgs/msg/Odometry"]}

    def get_topic_names_and_types(self):
        return list(self.topics.items())

    def get_publishers_info_by_topic(self, name):
        return []

    def get_subscriptions_info_by_topic(self, name):
        return []


def test_refresh_publishes_only_a_changed_graph():
    published = []
    node = FakeNode()
    rover = SimpleNamespace(config=CONFIG, runtime=SimpleNamespace(node=node, node_name="/rover_web"),
                            hub=SimpleNamespace(publish=lambda channel, data: published.append((channel, data))))
    browser = TopicBrowser(rover)
    browser.refresh()
    browser.refresh()
    assert [c for c, _ in published] == ["topics"]
    assert published[0][1]["node"] == "/rover_web"
    assert [t["name"] for t in published[0][1]["topics"]] == ["/odom"]
    node.topics["/scan"] = ["sensor_msgs/msg/LaserScan"]
    browser.refresh()
    assert len(published) == 2 and [t["name"] for t in published[1][1]["topics"]] == ["/odom", "/scan"]
    browser.close()
