"""A robot's alerts as the hub receives them: English for any reader, each one's id and values beside it,
and the hub's page shows them in its own language (the from_wire filter, the same as the browser's said)."""

from __future__ import annotations

import json

import pytest

from rover_web.web.api_messages import from_wire, with_wire
from rover_web.zenoh_link.robot import robot_summary
from tests.support.geofence_helpers import DOCK, breach_at


def breach_alerts(app) -> dict:
    rover = app.extensions["rover_web"]
    message = breach_at(DOCK, 0.5, 0.5)
    rover.hub.publish("geofence", with_wire({"state": "outside", "message": message}))
    # As it crosses Zenoh: JSON, signed, opened on the hub.
    return json.loads(json.dumps(robot_summary(rover, None)))


def test_a_breach_is_an_alert_in_english_with_its_wire_form(app_factory):
    line = breach_alerts(app_factory())
    breach = [a for a in line["alerts"] if "geofence" in a]
    assert breach == ["the robot left the geofence: (0.5000000, 0.5000000) is inside the geofence's "
                      "keep-out area 'dock'"]
    wires = line["alerts_i18n"]
    assert len(wires) == len(line["alerts"])
    assert wires[line["alerts"].index(breach[0])]["id"] == "the robot left the geofence: %(why)s"


@pytest.mark.parametrize("lang,expected", [
    ("es", "el robot salió de la geovalla: (0.5000000, 0.5000000) está dentro de zona prohibida 'dock' de la geovalla"),
    ("ja", "ロボットがジオフェンスの外に出ました: "
           "(0.5000000, 0.5000000) はジオフェンスの 禁止エリア 'dock' の内側にあります"),
])
def test_the_hub_shows_an_alert_in_its_pages_language(app_factory, lang, expected):
    app = app_factory()  # the hub's pages have the same filter (rover_web/i18n, for robot and hub alike)
    line = breach_alerts(app)
    i = next(i for i, a in enumerate(line["alerts"]) if "geofence" in a)
    with app.test_request_context("/", headers={"Accept-Language": lang}):
        assert from_wire(line["alerts_i18n"][i], line["alerts"][i]) == expected
        render = app.jinja_env.from_string("{{ english|from_wire(wire) }}").render
        assert render(english=line["alerts"][i], wire=line["alerts_i18n"][i]) == expected.replace("'", "&#39;")


@pytest.mark.parametrize("wire", [
    None, "text", {"id": 5}, {"id": "%(x)s", "values": []}, {"id": "%(x)s", "values": {"y": 1}},
    {"id": "%(x)d", "values": {"x": "a"}},
    {"id": "%(x)s", "values": {"x": [1]}},
    {"id": "%(x)s", "values": {"x": {"id": "%(x)s", "values": {"x": {"id": "%(x)s", "values": {"x": {
        "id": "%(x)s", "values": {"x": {"id": "%(x)s", "values": {"x": {"id": "deep"}}}}}}}}}}},
])
def test_a_wire_form_that_is_not_one_gives_the_english_sent_beside_it(app_factory, wire):
    with app_factory().test_request_context("/", headers={"Accept-Language": "es"}):
        assert from_wire(wire, "the English") == "the English"
