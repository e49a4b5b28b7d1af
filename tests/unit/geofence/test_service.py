"""The breach watch without ROS: which positions change the side, and when the e-stop engages."""

from rover_web.geofence.service import ESTOP_BY, GeofenceService
from tests.support.geofence_helpers import FENCE, IN_KEEP_OUT, INSIDE, OUTSIDE


class FakeStore:
    def __init__(self):
        self.doc, self.revision = None, 0

    def load(self):
        return (self.doc, self.revision) if self.doc else None

    def save(self, doc):
        self.doc, self.revision = doc, self.revision + 1
        return self.revision


class FakeEStop:
    def __init__(self):
        self.engaged_by = []

    def engage(self, by, via="api"):
        self.engaged_by.append((by, via))


class FakeHub:
    def __init__(self):
        self.published = []

    def publish(self, channel, data):
        self.published.append((channel, data))


def service(engage_estop=True):
    estop, hub = FakeEStop(), FakeHub()
    svc = GeofenceService(FakeStore(), estop, hub, max_vertices=100, engage_estop=engage_estop)
    svc.replace(FENCE)
    return svc, estop, hub


def at(svc, point):
    svc.note_position(*point)
    assert svc.pending.is_set()
    svc.evaluate()
    assert not svc.pending.is_set()
    return svc.state()["state"]


def test_each_crossing_is_one_event_and_each_breach_one_engage():
    svc, estop, hub = service()
    assert svc.state()["state"] == "unknown"
    assert at(svc, INSIDE) == "inside"
    hub.published.clear()
    assert at(svc, (0.31, 0.31)) == "inside" and hub.published == []  # same side: nothing sent
    assert at(svc, OUTSIDE) == "outside"
    assert estop.engaged_by == [(ESTOP_BY, "geofence")]
    assert at(svc, (1.6, 0.5)) == "outside" and len(estop.engaged_by) == 1  # still the same breach
    assert at(svc, INSIDE) == "inside"
    assert at(svc, IN_KEEP_OUT) == "outside" and len(estop.engaged_by) == 2
    sides = [data["state"] for channel, data in hub.published if channel == "geofence"]
    assert sides == ["outside", "inside", "outside"]


def test_without_the_setting_no_engage_and_no_fence_is_unknown():
    svc, estop, _ = service(engage_estop=False)
    assert at(svc, OUTSIDE) == "outside" and estop.engaged_by == []
    svc.replace({"type": "FeatureCollection", "features": []})
    svc.evaluate()
    assert svc.state()["state"] == "unknown" and svc.state()["revision"] == 2


def test_a_new_fence_rechecks_the_last_position():
    svc, _, _ = service(engage_estop=False)
    assert at(svc, INSIDE) == "inside"
    svc.replace({"type": "FeatureCollection", "features": [FENCE["features"][1]]})  # only the dock
    assert svc.pending.is_set()
    svc.evaluate()
    assert svc.state()["state"] == "inside"
    svc.replace({"type": "FeatureCollection", "features": [
        {**FENCE["features"][0], "geometry": {"type": "Polygon", "coordinates": [
            [[0.5, 0.5], [1, 0.5], [1, 1], [0.5, 1], [0.5, 0.5]]]}}]})
    svc.evaluate()
    assert svc.state()["state"] == "outside" and "keep-in" in svc.state()["message"]
