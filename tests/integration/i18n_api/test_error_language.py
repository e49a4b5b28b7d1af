"""An API error answers in the request's language: the same status and `error` code, its `message`
translated with the request's values in it; English unchanged, and an unknown language is English.

Real app, real routes, over HTTP. The expected texts come from the shipped catalogues
(translations/<lang>/LC_MESSAGES/api.po) filled with the values the request sent, and each is checked
to hold those values and to differ from the English.
"""

from __future__ import annotations

import re

import pytest
import requests
from babel.messages.pofile import read_po

from rover_web.config import ROOT

LANGUAGES = ("es", "ja")


def _catalogue(lang: str) -> dict[str, str]:
    with (ROOT / "translations" / lang / "LC_MESSAGES" / "api.po").open("rb") as f:
        return {m.id: m.string for m in read_po(f) if m.id}


@pytest.fixture
def server(live_server):
    # The real app: rover_web/i18n's Babel, its locale selector and the catalogues it compiled at
    # start from translations/ (api.po with messages.po).
    return live_server


def _ask(server, method: str, path: str, lang: str | None, **kwargs) -> requests.Response:
    headers = kwargs.pop("headers", {})
    if lang is not None:
        headers["Accept-Language"] = lang
    return requests.request(method, server.url + path, headers=headers, timeout=10, **kwargs)


# (method, path, request keywords, status, code, msgid, values the message must hold)
CASES = {
    "InvalidInput, values from the body": (
        "POST", "/api/waypoints", {"json": {"lng": 500, "lat": 0}}, 400, "out_of_range",
        "'%(where)s' must be between %(value)s and %(limit)s, got %(number)s",
        {"where": "lng", "value": "-180", "limit": "180", "number": "500"}),
    "ApiError from a route": (
        "GET", "/api/maps/no_such_map", {}, 404, "unknown_map",
        "no map named %(name)s; GET /api/maps lists them", {"name": "'no_such_map'"}),
    "the strict JSON reader": (
        "POST", "/api/waypoints", {"data": b'{"lng": NaN, "lat": 0}', "headers": {"Content-Type": "application/json"}},
        400, "non_finite", "%(name)s is not allowed: numbers must be finite", {"name": "NaN"}),
    "the guard before routing": (
        "POST", "/api/waypoints", {"data": b"lng=1", "headers": {"Content-Type": "text/plain"}}, 415,
        "unsupported_media_type", "send the body as JSON with the header Content-Type: application/json", {}),
    "Werkzeug's own 404": (
        "GET", "/api/no/such/route", {}, 404, "not_found",
        "The requested URL was not found on the server. If you entered the URL manually please check your "
        "spelling and try again.", {}),
}


@pytest.mark.parametrize("case", CASES)
def test_the_same_bad_request_answers_in_each_language_with_the_same_code(server, case):
    method, path, kwargs, status, code, msgid, values = CASES[case]
    english = _ask(server, method, path, None, **kwargs)
    assert english.status_code == status, english.text
    assert english.json() == {"error": code, "message": msgid % values}
    for lang in LANGUAGES:
        answer = _ask(server, method, path, lang, **kwargs)
        assert answer.status_code == status
        body = answer.json()
        assert body["error"] == code  # codes are identifiers clients branch on: never translated
        assert body["message"] == _catalogue(lang)[msgid] % values
        assert body["message"] != english.json()["message"]
        for value in values.values():
            assert value in body["message"]


def test_the_message_follows_the_preferred_language_and_its_weights(server):
    path, kwargs = "/api/waypoints", {"json": {"lng": 0}}
    japanese = _ask(server, "POST", path, "fr-CA, ja;q=0.9, es;q=0.5", **kwargs).json()["message"]
    spanish = _ask(server, "POST", path, "es-MX,es;q=0.9,en;q=0.8", **kwargs).json()["message"]
    assert re.search(r"[\u3040-\u30ff]", japanese)  # kana: Japanese, the first shipped language asked for
    assert japanese == _catalogue("ja")["'%(key)s' is required: send {\"lng\": <degrees east>, \"lat\": <degrees "
                                        "north>}"] % {"key": "lat"}
    assert spanish.startswith("'lat' es obligatorio")


def test_the_chosen_language_wins_over_the_browsers(server):
    # The page's language picker keeps the choice in the cookie rover_web_lang (and, signed in, in
    # the user's preferences): an API error follows it as the pages do; "auto" is Accept-Language's.
    path, kwargs = "/api/waypoints", {"json": {"lng": 500, "lat": 0}}
    chosen = _ask(server, "POST", path, "ja", cookies={"rover_web_lang": "es"}, **kwargs).json()
    automatic = _ask(server, "POST", path, "ja", cookies={"rover_web_lang": "auto"}, **kwargs).json()
    assert chosen == {"error": "out_of_range", "message": "'lng' debe estar entre -180 y 180; se recibió 500"}
    assert automatic["message"] == "'lng' は -180〜180 でなければなりません (受け取った値: 500)"


@pytest.mark.parametrize("lang", ["de", "fr-FR, de;q=0.5", "x-klingon", ""])
def test_an_unknown_or_empty_language_answers_in_english(server, lang):
    path, kwargs = "/api/waypoints", {"json": {"lng": 500, "lat": 0}}
    english = _ask(server, "POST", path, None, **kwargs).json()
    assert _ask(server, "POST", path, lang, **kwargs).json() == english
    assert english["message"] == "'lng' must be between -180 and 180, got 500"


def test_a_refusal_raised_deep_in_a_feature_is_translated_with_its_nested_reason(server):
    # A GeoJSON import refused in waypoints/geojson.py: an InvalidInput whose message holds a value
    # of its own (the feature's index), answered by the blueprint's error handler.
    doc = {"type": "FeatureCollection", "features": [{"type": "Feature", "geometry": {"type": "LineString"}}]}
    english = _ask(server, "POST", "/api/waypoints/geojson", None, json=doc)
    spanish = _ask(server, "POST", "/api/waypoints/geojson", "es", json=doc)
    assert english.status_code == spanish.status_code == 400
    assert english.json()["error"] == spanish.json()["error"] == "bad_geojson"
    assert english.json()["message"] == "features[0].geometry must be a Point, got 'LineString'"
    assert spanish.json()["message"] == "features[0].geometry debe ser un Point; se recibió 'LineString'"


def test_nothing_is_changed_by_a_refused_request_in_another_language(server):
    before = _ask(server, "GET", "/api/waypoints", None).json()
    for lang in (None, *LANGUAGES):
        assert _ask(server, "POST", "/api/waypoints", lang, json={"lng": 500, "lat": 0}).status_code == 400
    assert _ask(server, "GET", "/api/waypoints", "ja").json() == before


def test_a_teleop_error_frame_is_in_the_language_the_socket_was_opened_with(server):
    # The frame is refused on the socket's reader thread, outside any request: the language is the
    # one the handshake asked for, kept by the session.
    from tests.support.teleop_support import TeleopClient

    msgid = "'%(key)s' must be between %(low)s and %(high)s, got %(value)s"
    values = {"key": "linear", "low": "-1", "high": "1", "value": "5"}
    answers = {}
    for lang in (None, *LANGUAGES):
        client = TeleopClient(server.url, header=[f"Accept-Language: {lang}"] if lang else [])
        try:
            client.send({"linear": 5, "angular": 0})
            answers[lang] = client.wait_errors(1)[0]
        finally:
            client.close()
    assert {frame["error"] for frame in answers.values()} == {"out_of_range"}
    assert answers[None]["message"] == msgid % values
    for lang in LANGUAGES:
        assert answers[lang]["message"] == _catalogue(lang)[msgid] % values
        assert answers[lang]["message"] != answers[None]["message"]
