"""A sentence said to every viewer (api_messages.said): English where it is kept, its id and values beside
it for the browser, and every id it carries, a sentence within it included, in each language's browser
catalogue, so no part of it reaches a Spanish or Japanese page in English."""

from __future__ import annotations

import json

import pytest

from rover_web.config import ROOT
from rover_web.geofence.rules import parse_fence
from rover_web.geofence.service import breach_message
from rover_web.i18n.catalogues import compile_language
from rover_web.panels import spec
from rover_web.panels.msgs import field_kind
from rover_web.panels.state import PanelState
from rover_web.teleop.link import verdict
from rover_web.tf.buffer import TfBuffer
from rover_web.web.api_messages import Text, explain, said, with_wire
from tests.support.geofence_helpers import DOCK, area, collection, square


def ids(wire: dict) -> set[str]:
    found = {wire["id"]}
    for value in wire.get("values", {}).values():
        if isinstance(value, dict) and "id" in value:
            found |= ids(value)
    return found


def test_the_wire_form_is_the_msgid_and_values_beside_the_english():
    inner = said("keep-out area %(name)s", name="'dock'")
    outer = said("the robot left the geofence: %(why)s", why=inner)
    payload = with_wire({"state": "outside", "message": outer, "count": 3, "plain": "words"})
    assert payload["message"] == "the robot left the geofence: keep-out area 'dock'"
    why = {"id": "keep-out area %(name)s", "values": {"name": "'dock'"}}
    assert payload["message_i18n"] == {"id": "the robot left the geofence: %(why)s", "values": {"why": why}}
    assert "count_i18n" not in payload and "plain_i18n" not in payload and "state_i18n" not in payload
    assert said("no satellite lock").wire() == {"id": "no satellite lock"}
    # JSON as the event stream sends it: the English string, and the wire form beside it.
    assert json.loads(json.dumps(payload))["message"] == payload["message"]


def fence():
    return parse_fence(collection(area("keep_in", square(0, 0, 2, 2)), *DOCK["features"],
                                  area("keep_out", [[1.5, 1.5], [1.9, 1.5], [1.9, 1.9], [1.5, 1.5]])), 1000)


def said_by_the_server() -> list[Text]:
    """Sentences the real code says to every viewer, each kind of them."""
    f = fence()
    found = [breach_message(f.refusal(x, y)) for x, y in ((0.5, 0.5), (1.7, 1.6), (5, 5))]
    found += [verdict(*figures)[1] for figures in ((900, None, 0, 0), (None, 400, 0, 0), (None, None, 900, 0),
                                                   (None, None, 0, 0.5))]
    buffer = TfBuffer(cache_s=10)
    buffer.set_transform("a", "a", (0, 0, 0), (0, 0, 0, 1), 1, static=False)
    buffer.set_transform("a", "b", (0, 0, 0), (0, 0, 0, 2), 1, static=False)
    buffer.set_transform("c", "d", (0, 0, 0), (0, 0, 0, 1), 1, static=True)
    tree = buffer.frames(10**9)
    found += [w["message"] for w in tree["warnings"]] + [r["message"] for r in tree["rejected"]]
    (panel,) = spec.load(None, 2.0, field_kind)  # the drone's: a control allowed in either of two states
    state = PanelState(panel, lambda: 1000.0)
    refused = [c["reason"] for c in state.view()["controls"].values() if c["reason"]]  # locked
    state.unlock()
    state.update("status", "Flying")
    refused += [c["reason"] for c in state.view()["controls"].values() if c["reason"]]
    assert any(" or " in r for r in refused)
    found += refused
    assert all(isinstance(t, Text) for t in found) and len(found) >= 10
    return found


@pytest.mark.parametrize("lang", ["es", "ja"])
def test_every_id_a_said_sentence_carries_is_in_the_browsers_catalogue(lang):
    browser = json.loads(compile_language(ROOT / "translations" / lang, lang).browser)["messages"]
    missing = sorted({i for text in said_by_the_server() for i in ids(text.wire())} - set(browser))
    assert missing == []


def test_an_api_reason_within_a_said_sentence_is_not_in_the_browsers_catalogue():
    # The rule the sites follow: a reason shown to every viewer is said, not explained. This is what
    # the check above would catch, were a site to pass an explain() reason on.
    browser = json.loads(compile_language(ROOT / "translations" / "es", "es").browser)["messages"]
    reason = explain("the e-stop is engaged: nobody takes control until it is released")
    assert reason.msgid not in browser
