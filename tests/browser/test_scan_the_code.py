"""The Scan the Code panel in Chromium, driven by a real ROS publisher in another process."""

import time

import pytest
from playwright.sync_api import expect

pytestmark = [pytest.mark.browser, pytest.mark.ros]

STRING = "std_msgs/msg/String"
LIGHTS = "/light_sequence"
MARKUP = '<img src=x onerror="window.__pwned=1">'
SVG = '<svg onload="window.__pwned=2"></svg>'


def light_publisher(ros_peer, rover):
    """A peer publishing on /light_sequence that the app has already heard once."""
    peer = ros_peer()
    peer.advertise(LIGHTS, STRING)
    peer.wait_match(LIGHTS)
    deadline = time.monotonic() + 10
    while not any(t["topic"] == LIGHTS and t["count"] for t in rover.runtime.topic_stats(3.0)):
        assert time.monotonic() < deadline, "the app never heard the peer"
        peer.publish(LIGHTS, {"data": "black"})
        time.sleep(0.05)
    return peer


def open_dashboard(page, server):
    page.goto(server.url + "/")
    expect(page.locator("#link-server")).to_have_attribute("data-state", "live")


def test_boxes_fill_in_order_and_reset_on_black(live_server, ros_peer, page):
    peer = light_publisher(ros_peer, live_server.rover)
    open_dashboard(page, live_server)
    boxes = page.locator("#stc-boxes .stc-box")
    expect(boxes).to_have_count(3)
    expect(page.locator("#stc-code")).to_have_text("no code yet")
    steps = [("Red", ["red", "black", "black"]), ("red", ["red", "black", "black"]),  # same light still on
             ("green", ["red", "green", "black"]), ("BLUE", ["red", "green", "blue"]),
             ("black", ["black", "black", "black"])]
    for text, expected in steps:
        peer.publish(LIGHTS, {"data": text})
        for box, colour in zip(range(3), expected, strict=True):
            expect(boxes.nth(box)).to_have_attribute("data-colour", colour)
            expect(boxes.nth(box).locator(".stc-box-name")).to_have_text(colour)
        expect(page.locator("#stc-lamp")).to_have_attribute("data-colour", text.lower())
        if text == "green":  # the box is painted in its colour, not just labelled
            assert boxes.nth(1).evaluate("el => getComputedStyle(el).backgroundColor") == "rgb(34, 177, 76)"
            assert boxes.nth(2).evaluate("el => getComputedStyle(el).backgroundColor") == "rgb(5, 7, 10)"
    # Three colours then black: the detected code, large.
    chips = page.locator("#stc-code .stc-chip")
    expect(chips).to_have_text(["red", "green", "blue"])
    expect(page.locator("#stc-code")).to_have_attribute("data-confirmed", "yes")
    expect(page.locator("#stc-code-meta")).to_contain_text("confidence 1")
    assert float(chips.first.evaluate("el => parseFloat(getComputedStyle(el).fontSize)")) >= 20
    expect(page.locator("#stc-history li")).to_have_count(1)
    # More than three colours is shown as an invalid cycle while it happens.
    for text in ["yellow", "red", "green", "blue"]:
        peer.publish(LIGHTS, {"data": text})
    expect(boxes.nth(2)).to_have_attribute("data-colour", "green")
    expect(page.locator("#stc-cycle")).to_have_text("this cycle is invalid: too many colours")
    peer.publish(LIGHTS, {"data": "black"})
    expect(page.locator("#stc-invalid")).to_have_text("1")
    expect(page.locator("#stc-code .stc-chip")).to_have_text(["red", "green", "blue"])  # the last good code stays
    assert page.watch.console_errors == [] and page.watch.offhost == []


def test_markup_in_a_colour_string_is_shown_as_text(live_server_factory, ros_peer, page):
    # The first box is filled before the page opens: a load that takes longer than the light's
    # 3 s staleness (a busy machine) would start a new cycle and lose it.
    live_server = live_server_factory(ROVER_WEB_LIGHT_STALE_AFTER_S=60.0)
    peer = light_publisher(ros_peer, live_server.rover)
    peer.publish(LIGHTS, {"data": MARKUP})
    deadline = time.monotonic() + 10
    while live_server.rover.hub.latest("light_sequence")["light"] != "unknown":
        assert time.monotonic() < deadline
        time.sleep(0.02)
    # Rendered by the server into the page...
    open_dashboard(page, live_server)
    light = page.locator("#stc-light")
    expect(light).to_have_text(f"unknown: {MARKUP}")
    # ...and pushed over SSE into the live page.
    peer.publish(LIGHTS, {"data": "red"})
    expect(light).to_have_text("red")
    peer.publish(LIGHTS, {"data": SVG})
    expect(light).to_have_text(f"unknown: {SVG}")
    expect(page.locator("#stc-unknown")).to_have_text("2")
    boxes = page.locator("#stc-boxes .stc-box")
    for box, colour in enumerate(["unknown", "red", "unknown"]):
        expect(boxes.nth(box)).to_have_attribute("data-colour", colour)
    page.wait_for_timeout(300)  # give a broken page time to load the image and run its handler
    assert page.locator("#scan-the-code img, #scan-the-code svg").count() == 0
    assert page.evaluate("window.__pwned") is None
    assert page.watch.console_errors == [] and page.watch.offhost == []


def test_light_tower_show_hide_toggle_is_remembered(live_server, page):
    open_dashboard(page, live_server)
    tower, toggle = page.locator("#stc-tower"), page.locator("#stc-tower-toggle")
    expect(tower).to_be_visible()
    expect(toggle).to_have_text("Hide")
    toggle.click()
    expect(tower).to_be_hidden()
    expect(toggle).to_have_text("Show")
    expect(toggle).to_have_attribute("aria-expanded", "false")
    page.reload()
    expect(page.locator("#stc-tower")).to_be_hidden()
    page.locator("#stc-tower-toggle").click()
    expect(page.locator("#stc-tower")).to_be_visible()
    expect(page.locator("#stc-boxes")).to_be_visible()  # the boxes never hide with the tower


def test_freshness_shows_live_then_stale(live_server_factory, ros_peer, page):
    server = live_server_factory(ROVER_WEB_LIGHT_STALE_AFTER_S=1.0)
    open_dashboard(page, server)
    pill = page.locator("#stc-fresh")
    expect(pill).to_have_attribute("data-state", "no_data")
    light_publisher(ros_peer, server.rover)
    expect(pill).to_have_attribute("data-state", "ok")
    expect(pill).to_have_text("live")
    expect(pill).to_have_attribute("data-state", "stale", timeout=5000)
    expect(pill).to_have_text("stale")
    expect(page.locator("#scan-the-code")).to_have_class("card stc stc-stale")
