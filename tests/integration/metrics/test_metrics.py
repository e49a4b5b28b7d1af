"""GET /metrics on a robot's rover_web: the exposition as Prometheus' own client parses it, labels
bounded whatever paths are asked, the token rule when exposed, and off with ROVER_WEB_METRICS=off."""

from __future__ import annotations

import random
import string
import time

import pytest
from prometheus_client.parser import text_string_to_metric_families

from tests.support.auth import bearer


def families(text: str) -> dict:
    return {f.name: f for f in text_string_to_metric_families(text)}


def samples(family, **labels) -> list:
    return [s for s in family.samples if all(s.labels.get(k) == v for k, v in labels.items())]


def test_the_exposition_parses_with_each_robot_s_and_the_process_s_figures(app_factory):
    app = app_factory(ROVER_WEB_ROBOTS=[{"name": "boat"}, {"name": "drone"}])
    client = app.test_client()
    client.post("/robots/drone/api/estop", json={"engaged": True})
    reply = client.get("/metrics")
    assert reply.status_code == 200
    assert reply.headers["Content-Type"].startswith("text/plain; version=")
    found = families(reply.get_data(as_text=True))
    for name in ("rover_web_estop_engaged", "rover_web_operator_present", "rover_web_robot_link",
                 "rover_web_teleop_stops", "rover_web_viewers", "rover_web_recording_active",
                 "rover_web_recording_bytes", "rover_web_geofence_refused", "rover_web_http_requests",
                 "process_cpu_seconds", "process_resident_memory_bytes", "process_open_fds", "process_threads"):
        assert name in found, name
    assert {s.labels["robot"]: s.value for s in found["rover_web_estop_engaged"].samples} == {"boat": 0, "drone": 1}
    assert {(s.labels["robot"], s.labels["reason"]) for s in found["rover_web_teleop_stops"].samples} == {
        (r, why) for r in ("boat", "drone") for why in ("deadman", "link")}
    # No battery message yet: left out, never NaN.
    assert "rover_web_battery_percent" not in found or not found["rover_web_battery_percent"].samples
    assert [s.value for s in samples(found["rover_web_robot_link"], robot="boat", state="no_data")] == [1.0]
    assert {s.labels["kind"] for s in samples(found["rover_web_viewers"], robot="boat")} >= {"events", "mjpeg"}
    estop_posts = samples(found["rover_web_http_requests"], route="/api/estop", method="POST", status="200")
    assert estop_posts and estop_posts[0].value == 1  # /robots/drone/api/estop counted under its template
    assert found["process_threads"].samples[0].value > 1


def test_route_labels_stay_bounded_under_a_fuzz_of_paths(app_factory):
    app = app_factory(ROVER_WEB_ROBOTS=[{"name": "boat"}, {"name": "drone"}])
    client = app.test_client()
    rng = random.Random(42)
    alphabet = string.ascii_letters + string.digits + "-_.~%/"
    prefixes = ["/", "/api/", "/robots/boat/", "/robots/drone/api/", "/robots/nobody/", "/static/", "/tiles/1/2/",
                "/api/recordings/", "/api/waypoints/", "/metrics/"]
    for _ in range(400):
        path = rng.choice(prefixes) + "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 30)))
        client.open(path.replace("//", "/"), method=rng.choice(["GET", "POST", "DELETE", "PROPFIND"]))
    found = families(client.get("/metrics").get_data(as_text=True))
    rules = {rule.rule for rule in app.url_map.iter_rules()} | {"unmatched"}
    routes = {s.labels["route"] for s in found["rover_web_http_requests"].samples}
    assert routes <= rules, routes - rules
    assert {s.labels["method"] for s in found["rover_web_http_requests"].samples} <= {
        "GET", "POST", "DELETE", "other"}
    # A few dozen series at most, whatever 400 random paths asked for.
    assert len(found["rover_web_http_requests"].samples) < 120
    assert sum(s.value for s in found["rover_web_http_requests"].samples) >= 400


def test_exposed_it_needs_a_viewer_s_token_and_answers_401_not_a_sign_in_page(signed_app):
    client = signed_app.test_client()
    refused = client.get("/metrics")
    assert refused.status_code == 401 and refused.headers["WWW-Authenticate"].startswith("Bearer")
    assert client.get("/metrics", headers={"Authorization": "Bearer not-a-token"}).status_code == 401
    for role in ("viewer", "operator", "admin"):
        reply = client.get("/metrics", headers=bearer(signed_app, role))
        assert reply.status_code == 200 and b"rover_web_estop_engaged" in reply.data


def test_off_is_a_404(app_factory):
    client = app_factory(ROVER_WEB_METRICS="off").test_client()
    assert client.get("/metrics").status_code == 404
    assert "/metrics" not in client.get("/api/openapi.json").get_json()["paths"]


@pytest.mark.parametrize("settings, url", [
    ({"ROVER_WEB_HOST": "127.0.0.1", "ROVER_WEB_PORT": 5001}, "http://127.0.0.1:5001"),
    ({"ROVER_WEB_HOST": "::1", "ROVER_WEB_PORT": 5001, "ROVER_WEB_TLS_CERT": "c.pem"}, "https://[::1]:5001"),
    ({"ROVER_WEB_HOST": "0.0.0.0,10.0.0.5", "ROVER_WEB_PORT": 80}, "http://10.0.0.5:80"),
    ({"ROVER_WEB_HOST": "0.0.0.0"}, None),
    ({"ROVER_WEB_HOST": None}, None),
    ({"ROVER_WEB_HOST": "127.0.0.1", "ROVER_WEB_PUBLIC_URL": "https://boat.example.org"}, "https://boat.example.org"),
])
def test_a_robot_s_own_address_is_derived_when_it_has_no_public_url(settings, url):
    from rover_web.zenoh_link.session import own_url

    assert own_url({"ROVER_WEB_PUBLIC_URL": None, "ROVER_WEB_PORT": 5000, "ROVER_WEB_TLS_CERT": None,
                    **settings}) == url


def test_what_the_features_count_moves_in_the_scrape(app_factory, tmp_path):
    """The collectors read the features' own counters: a goal refused by the geofence, an e-stop engaged
    and released, a request's route and status."""
    from tests.support.geofence_helpers import FENCE, INSIDE, OUTSIDE

    client = app_factory(ROVER_WEB_MAP_TILES=str(tmp_path / "no-tiles")).test_client()

    def scrape() -> dict:
        return families(client.get("/metrics").get_data(as_text=True))

    assert scrape()["rover_web_geofence_refused"].samples[0].value == 0
    assert client.put("/api/geofence", json=FENCE).status_code == 200
    assert client.post("/api/waypoints", json={"lng": OUTSIDE[0], "lat": OUTSIDE[1]}).status_code == 422
    assert client.post("/api/waypoints", json={"lng": OUTSIDE[0], "lat": OUTSIDE[1]}).status_code == 422
    assert client.post("/api/waypoints", json={"lng": INSIDE[0], "lat": INSIDE[1]}).status_code in (200, 201)
    found = scrape()
    assert [s.value for s in found["rover_web_geofence_refused"].samples if s.name.endswith("_total")] == [2]
    refused = samples(found["rover_web_http_requests"], route="/api/waypoints", method="POST", status="422")
    assert refused[0].value == 2
    client.post("/api/estop", json={"engaged": True})
    found = scrape()
    assert found["rover_web_estop_engaged"].samples[0].value == 1
    assert abs(found["rover_web_estop_engaged_since_seconds"].samples[0].value - time.time()) < 5
    client.post("/api/estop", json={"engaged": False})
    found = scrape()
    assert found["rover_web_estop_engaged"].samples[0].value == 0
    assert not found.get("rover_web_estop_engaged_since_seconds") or \
        not found["rover_web_estop_engaged_since_seconds"].samples
