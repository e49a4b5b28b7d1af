"""The fleet's pure parts: the graph-wide hub, the shutdown order, a robot's mode."""

from rover_web.core.fleet import Fleet, FleetHub
from rover_web.events.hub import EventHub
from rover_web.fleet.summary import mode


def test_a_graph_wide_channel_reaches_every_robots_stream():
    hubs = [EventHub(), EventHub()]
    fleet_hub = FleetHub(hubs)
    fleet_hub.register("topics")
    assert all("topics" in hub.channels for hub in hubs)
    fleet_hub.publish("topics", {"n": 1})
    assert [hub.latest("topics") for hub in hubs] == [{"n": 1}, {"n": 1}]
    with hubs[1].subscribe(["topics"]) as subscription:
        assert b'"n":1' in subscription.snapshot()
        assert fleet_hub.client_count == 1
    fleet_hub.close()
    assert all(hub.closed for hub in hubs)


class Recorder:
    """Stands in for a Rover and the runtime: only the order of the shutdown calls matters here."""

    def __init__(self, name, calls):
        self.name, self.calls, self.fleet = name, calls, None
        self.robot = type("R", (), {"name": name})()
        self.config = {"ROVER_WEB_SHUTDOWN_TIMEOUT_S": 1.0}

    def halt(self):
        self.calls.append(f"halt {self.name}")

    def wind_down(self):
        self.calls.append(f"wind_down {self.name}")

    def stop(self, timeout_s):
        self.calls.append(f"stop {self.name}")


def test_every_robot_halts_before_anything_winds_down_and_ros_stops_last_once():
    calls = []
    robots = [Recorder("boat", calls), Recorder("drone", calls)]
    graph = Recorder("graph", calls)
    fleet = Fleet(robots, Recorder("runtime", calls), graph)
    assert [r.fleet for r in (*robots, graph)] == [fleet] * 3
    fleet.shutdown()
    fleet.shutdown()
    assert calls == ["halt boat", "halt drone", "halt graph", "wind_down graph", "wind_down drone",
                     "wind_down boat", "stop runtime"]
    assert fleet.get("drone") is robots[1] and fleet.get("graph") is None and fleet.names == ["boat", "drone"]


def test_one_robot_is_its_own_graph_scope():
    calls = []
    robot = Recorder("robot", calls)
    fleet = Fleet([robot], Recorder("runtime", calls))
    assert fleet.graph is robot
    fleet.shutdown()
    assert calls == ["halt robot", "wind_down robot", "stop runtime"]


def test_the_mode_says_first_what_an_operator_must_know_first():
    moving = {"moving": True, "holder": {"id": 1, "name": "ada"}}
    assert mode({"engaged": True}, moving) == "estop"
    assert mode({"engaged": False}, moving) == "driving"
    assert mode({"engaged": False}, {"moving": False, "holder": {"id": 1, "name": "ada"}}) == "operator"
    assert mode({"engaged": False}, {"moving": False, "holder": None}) == "idle"
