"""Hypothesis over request bodies (and ids) for every waypoints route: never a 5xx, a refused request
changes nothing, nothing invalid is ever stored, and exactly the acknowledged waypoints and
missions reach ROS (checked by a real subscriber in another process)."""

import json
import math
import sqlite3
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rover_web import create_app
from rover_web.waypoints.service import WaypointsService
from tests.support.rospeer import RosPeer
from tests.support.waypoint_helpers import FLOAT64_MULTI_ARRAY

MAX_WAYPOINTS = 12
FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))

KEYS = st.sampled_from(["lng", "lat", "label", "index", "revision", "type", "features", "geometry", "coordinates",
                        "properties", "name", "id"]) | st.text(max_size=8)
NUMBERS = (st.integers(min_value=-10 ** 30, max_value=10 ** 30) | st.floats(allow_nan=False, allow_infinity=False)
           | st.sampled_from([0, -0.0, 90, -90, 180, -180, 90.0000001, 180.0000001, 1e308, -1e-308, 5e-324]))
SCALARS = st.none() | st.booleans() | NUMBERS | st.text(max_size=100)
JSON = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(KEYS, inner, max_size=5),
                    max_leaves=12)
COORD = NUMBERS | SCALARS
LNG = st.floats(-180, 180) | st.floats(-180, 180) | COORD  # valid two times in three, so acceptances happen too
LAT = st.floats(-90, 90) | st.floats(-90, 90) | COORD
LABEL = (st.none() | st.text(st.characters(min_codepoint=32, exclude_categories=("Cs", "Cc")), max_size=80)
         | st.text(max_size=90) | NUMBERS)
POSITION = st.fixed_dictionaries({"lng": LNG, "lat": LAT}, optional={"label": LABEL})
EDIT = st.fixed_dictionaries({}, optional={"lng": LNG, "lat": LAT, "label": LABEL,
                                           "index": st.integers(-3, 30) | JSON, "id": JSON})
FEATURE = st.fixed_dictionaries({
    "type": st.sampled_from(["Feature"] * 6 + ["Point", "feature"]),
    "geometry": st.fixed_dictionaries({"type": st.sampled_from(["Point"] * 6 + ["LineString"]),
                                       "coordinates": st.tuples(LNG, LAT).map(list) | st.lists(COORD, max_size=4)})
                | JSON,
}, optional={"properties": st.dictionaries(st.sampled_from(["label", "name", "x"]), LABEL, max_size=2) | JSON})
GEOJSON = st.fixed_dictionaries({"type": st.sampled_from(["FeatureCollection"] * 4 + ["Feature"]),
                                 "features": st.lists(FEATURE, max_size=MAX_WAYPOINTS + 2) | JSON})
RAW = st.binary(max_size=200) | st.sampled_from([b"", b"{", b"NaN", b'{"lng": NaN, "lat": 1}',
                                                  b'{"lng": 1, "lat": Infinity}', b'{"lng": 1e999, "lat": 1}',
                                                  b"[" * 5000, b'"\\ud800"',
                                                  b'{"lng": 1, "lat": 1, "label": "\\ud800"}'])


def encoded(value) -> bytes:
    return json.dumps(value).encode()


BODY = st.one_of(POSITION.map(encoded), POSITION.map(encoded), EDIT.map(encoded), JSON.map(encoded), RAW)
CONTENT_TYPE = st.sampled_from(["application/json"] * 16 + ["text/plain", "application/geo+json", None,
                                                             "application/json; charset=utf-8"])


class Harness:
    """One app (own node, real SQLite), one subscriber process, and the ledger of what must be heard."""

    def __init__(self, db_path):
        self.app = create_app({"TESTING": True, "ROVER_WEB_DB_PATH": str(db_path), "ROVER_WEB_HOST": "127.0.0.1",
                               "ROVER_WEB_MAX_WAYPOINTS": MAX_WAYPOINTS})
        self.db_path = db_path
        self.client = self.app.test_client()
        self.store = self.app.extensions["rover_web"].feature(WaypointsService).store
        self.peer = RosPeer("fuzz_listener")
        for topic in ("/waypoints", "/mission"):
            self.peer.subscribe(topic, FLOAT64_MULTI_ARRAY, qos=1000)  # a listener that must not drop any
            self.peer.wait_match(topic)
        self.expected = {"/waypoints": [], "/mission": []}
        deadline = time.monotonic() + 15
        while not (self.peer.received("/waypoints") and self.peer.received("/mission")):
            assert time.monotonic() < deadline, "the subscriber never heard the app"
            self.client.post("/api/waypoints", json={"lng": 0.25, "lat": 0.25})
            self.client.post("/api/waypoints/send", json={})
            time.sleep(0.1)
        self.client.delete("/api/waypoints")
        time.sleep(0.3)
        self.reset_ledger()

    def reset_ledger(self):
        for topic in self.expected:
            self.peer.clear(topic)
            self.expected[topic] = []

    def request(self, method: str, path: str, body: bytes | None = None, content_type: str | None = "application/json"):
        before = self.store.mission()
        kwargs = {}
        if body is not None:
            kwargs["data"] = body
            if content_type:
                kwargs["content_type"] = content_type
        response = self.client.open(path, method=method, **kwargs)
        assert response.status_code < 500, (method, path, body, response.get_data()[:300])
        after = self.store.mission()
        if response.status_code >= 400:
            if method != "GET" or path.startswith("/api/"):  # a browser's GET of a missing page gets HTML
                assert response.is_json, (method, path, response.status_code)
                assert set(response.get_json()) == {"error", "message"}
            assert after == before, f"a refused {method} {path} changed the mission"
        elif method == "POST" and path in ("/waypoints", "/api/waypoints"):
            w = response.get_json()["waypoint"]
            self.expected["/waypoints"].append([w["lng"], w["lat"]])
        elif method == "POST" and path == "/api/waypoints/send":
            self.expected["/mission"].append([v for w in before.waypoints for v in (w.lng, w.lat)])
        self.check_stored()
        return response

    def check_stored(self):
        conn = sqlite3.connect(self.db_path)
        try:
            rows = conn.execute("SELECT position, lng, lat, label FROM waypoints ORDER BY position").fetchall()
        finally:
            conn.close()
        assert [r[0] for r in rows] == list(range(len(rows))) and len(rows) <= MAX_WAYPOINTS
        for _, lng, lat, label in rows:
            assert isinstance(lng, float) and math.isfinite(lng) and -180 <= lng <= 180
            assert isinstance(lat, float) and math.isfinite(lat) and -90 <= lat <= 90
            assert isinstance(label, str) and len(label) <= 80 and all(ord(c) >= 32 for c in label)

    def check_published(self):
        """Exactly the acknowledged messages, in order, each valid; nothing for any refusal."""
        for topic, expected in self.expected.items():
            deadline = time.monotonic() + 10
            while len(self.peer.received(topic)) < len(expected) and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.2)
            got = [m["msg"]["data"] for m in self.peer.received(topic)]
            assert got == expected, f"{topic}: {len(got)} messages heard, {len(expected)} acknowledged"
            for data in got:
                assert all(math.isfinite(v) for v in data)
                assert all(-180 <= lng <= 180 and -90 <= lat <= 90
                           for lng, lat in zip(data[::2], data[1::2], strict=True))

    def close(self):
        self.peer.close()
        self.app.extensions["rover_web"].shutdown()


@pytest.fixture(scope="module")
def harness(tmp_path_factory):
    h = Harness(tmp_path_factory.mktemp("fuzz") / "fuzz.sqlite3")
    yield h
    h.close()


@pytest.fixture
def fresh(harness):
    harness.client.delete("/api/waypoints")
    harness.reset_ledger()
    yield harness
    harness.check_published()


def draw_target(data, harness) -> str:
    """A waypoint id for a path: mostly one that exists (drawn as a position, so the drawing does not
    depend on the database's state, as Hypothesis requires), sometimes anything at all."""
    kind = data.draw(st.sampled_from(["existing", "existing", "number", "text"]))
    position = data.draw(st.integers(0, MAX_WAYPOINTS))
    number = data.draw(st.integers(-5, 10 ** 25))
    text = data.draw(st.text(alphabet="0123456789abc%-._", max_size=12))
    ids = [w.id for w in harness.store.mission().waypoints]
    if kind == "existing" and ids:
        return str(ids[position % len(ids)])
    return str(number) if kind == "number" else text


@pytest.mark.parametrize("route", ["/waypoints", "/api/waypoints"])
def test_fuzz_adding(fresh, route):
    @FUZZ
    @given(body=BODY, content_type=CONTENT_TYPE)
    def run(body, content_type):
        if len(fresh.store.mission().waypoints) >= MAX_WAYPOINTS - 1 and body[:1] == b"{":
            fresh.client.delete("/api/waypoints")  # keep room, so valid bodies are accepted too
        fresh.request("POST", route, body, content_type)

    run()
    assert fresh.expected["/waypoints"], "the fuzzer never produced an acceptable waypoint"


def test_fuzz_patching(fresh):
    @FUZZ
    @given(data=st.data(), body=BODY, content_type=CONTENT_TYPE)
    def run(data, body, content_type):
        if not fresh.store.mission().waypoints:
            for lng in (1.0, 2.0, 3.0):
                fresh.client.post("/api/waypoints", json={"lng": lng, "lat": 1.0})
            fresh.expected["/waypoints"] += [[1.0, 1.0], [2.0, 1.0], [3.0, 1.0]]
        fresh.request("PATCH", f"/api/waypoints/{draw_target(data, fresh)}", body, content_type)

    run()


def test_fuzz_deleting_one_and_all(fresh):
    @FUZZ
    @given(data=st.data(), body=st.none() | BODY)
    def run(data, body):
        if len(fresh.store.mission().waypoints) < 2:
            for lng in (4.0, 5.0, 6.0):
                fresh.client.post("/api/waypoints", json={"lng": lng, "lat": 2.0})
            fresh.expected["/waypoints"] += [[4.0, 2.0], [5.0, 2.0], [6.0, 2.0]]
        clear_all = data.draw(st.integers(0, 9)) == 0
        path = "/api/waypoints" if clear_all else f"/api/waypoints/{draw_target(data, fresh)}"
        fresh.request("DELETE", path, body, data.draw(CONTENT_TYPE))

    run()


def test_fuzz_sending(fresh):
    @FUZZ
    @given(data=st.data(), body=st.none() | BODY
           | st.fixed_dictionaries({"revision": JSON}).map(encoded))
    def run(data, body):
        if data.draw(st.booleans()) and len(fresh.store.mission().waypoints) < MAX_WAYPOINTS:
            fresh.client.post("/api/waypoints", json={"lng": 7.5, "lat": -3.25})
            fresh.expected["/waypoints"].append([7.5, -3.25])
        if data.draw(st.integers(0, 9)) == 0:
            fresh.client.delete("/api/waypoints")
        if data.draw(st.booleans()):
            body = encoded({"revision": fresh.store.mission().revision})
        fresh.request("POST", "/api/waypoints/send", body, data.draw(CONTENT_TYPE))

    run()
    assert fresh.expected["/mission"], "the fuzzer never sent a mission"


def test_fuzz_importing_geojson(fresh):
    @FUZZ
    @given(body=st.one_of(GEOJSON.map(encoded), GEOJSON.map(encoded), BODY), content_type=CONTENT_TYPE)
    def run(body, content_type):
        fresh.request("POST", "/api/waypoints/geojson", body, content_type)

    run()


def test_fuzz_reading_routes(fresh):
    @FUZZ
    @given(path=st.sampled_from(["/api/waypoints", "/api/waypoints/geojson", "/waypoints", "/tiles"])
           .flatmap(lambda p: st.just(p)
                    | st.text(alphabet="0123456789/-.?=&abcxyz%", max_size=30).map(lambda s: p + s)))
    def run(path):
        fresh.request("GET", path)

    run()
