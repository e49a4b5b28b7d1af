"""Each default layout in Chromium on a desktop (1400×1000) and a phone (390×844), the policy enforced.

The page shows the layout's cards in its order, placed from their cells on the desktop and stacked on
the phone, keeps the e-stop and the link pills outside the layout, opens one event stream with only
the channels its cards need, and no video without a camera card.
"""

import os
import re

import pytest
import requests

from tests.browser.test_csp import RECORD_VIOLATIONS
from tests.conftest import PageWatch

pytestmark = pytest.mark.browser

DESKTOP = {"width": 1400, "height": 1000}
PHONE = {"width": 390, "height": 844}
DEFAULTS = ["Boat", "Rover", "Drone", "Everything"]
# base.html's, outside every layout: the e-stop, the geofence banner and the Errors pill.
ALWAYS = {"estop", "geofence", "rosout_health"}
VIDEO_PATHS = ("/stream", "/snapshot", "/api/camera/whep")

BOXES = """() => [...document.querySelectorAll('#layout > [data-card]')].map((el) => {
  const r = el.getBoundingClientRect();
  return {type: el.dataset.card, x: +el.dataset.x, y: +el.dataset.y, w: +el.dataset.w, h: +el.dataset.h,
          left: r.left, right: r.right, top: r.top + scrollY, bottom: r.bottom + scrollY, width: r.width,
          height: r.height};
})"""


def choose(server, name: str) -> dict:
    """Choose the layout named `name` for every browser (sign-in is off) and return it."""
    listing = requests.get(server.url + "/api/layouts", timeout=5).json()["layouts"]
    layout_id = next(x["id"] for x in listing if x["name"] == name)
    assert requests.put(server.url + "/api/me/layout", json={"id": layout_id}, timeout=5).status_code == 200
    return requests.get(f"{server.url}/api/layouts/{layout_id}", timeout=5).json()


def open_dashboard(browser, server, viewport):
    phone = viewport == PHONE
    context = browser.new_context(viewport=viewport, is_mobile=phone, has_touch=phone)  # the policy enforced
    context.add_init_script(RECORD_VIOLATIONS)
    page = context.new_page()
    page.watch = PageWatch(page)
    page.requested = []
    page.on("request", lambda r: page.requested.append(r.url.removeprefix(server.url)))
    page.goto(server.url + "/")
    page.wait_for_selector("body[data-link='up']", timeout=15000)
    page.wait_for_load_state("networkidle")
    return context, page


def check_always_there(page, viewport):
    for selector in ("#estop-engage", "#link-server", "#link-robot"):
        box = page.locator(selector).bounding_box()
        assert box and box["width"] > 0 and box["height"] > 0, selector
        assert box["x"] >= 0 and box["x"] + box["width"] <= viewport["width"], f"{selector} is off screen: {box}"


def check_clean(page):
    assert page.evaluate("window.__csp") == []
    assert page.watch.console_errors == []
    assert page.watch.offhost == []


@pytest.mark.parametrize("name", DEFAULTS)
def test_a_default_layout_on_a_desktop_places_every_card_from_its_cell(live_server, browser, name):
    layout = choose(live_server, name)
    context, page = open_dashboard(browser, live_server, DESKTOP)
    try:
        boxes = page.evaluate(BOXES)
        assert [b["type"] for b in boxes] == [c["type"] for c in layout["cards"]]
        column = (DESKTOP["width"] - 40) / 12  # about: the page's padding aside
        for b in boxes:
            assert b["height"] > 40, b
            assert abs(b["width"] - b["w"] * column) < column, f"{b['type']} is not {b['w']} columns wide: {b}"
        for a in boxes:
            for b in boxes:
                if a["x"] + a["w"] <= b["x"] and a["y"] < b["y"] + b["h"] and b["y"] < a["y"] + a["h"]:
                    assert a["right"] <= b["left"] + 1, f"{a['type']} is not left of {b['type']}"
                if a["y"] + a["h"] <= b["y"] and a["x"] < b["x"] + b["w"] and b["x"] < a["x"] + a["w"]:
                    assert a["bottom"] <= b["top"] + 1, f"{a['type']} is not above {b['type']}"
                if a["y"] == b["y"]:
                    assert abs(a["top"] - b["top"]) < 2, f"{a['type']} and {b['type']} start on one row"
        check_always_there(page, DESKTOP)
        check_clean(page)
    finally:
        context.close()


@pytest.mark.parametrize("name", DEFAULTS)
def test_a_default_layout_on_a_phone_stacks_in_layout_order_without_sideways_scroll(live_server, browser, name):
    layout = choose(live_server, name)
    context, page = open_dashboard(browser, live_server, PHONE)
    try:
        boxes = page.evaluate(BOXES)
        assert [b["type"] for b in boxes] == [c["type"] for c in layout["cards"]]
        for above, below in zip(boxes, boxes[1:], strict=False):
            assert below["top"] >= above["bottom"], f"{below['type']} is not below {above['type']}"
        for b in boxes:
            assert b["left"] >= 0 and b["right"] <= PHONE["width"], b
        overflow = page.evaluate("document.documentElement.scrollWidth - document.documentElement.clientWidth")
        assert overflow <= 0, f"the page is {overflow}px wider than the phone"
        check_always_there(page, PHONE)
        check_clean(page)
    finally:
        context.close()


def page_modules(live_server, requested):
    """The modules of the page's bundle (rover_web/web/bundles.py), by the bundle's source map."""
    bundle = [u for u in requested if re.fullmatch(r"/static/js/bundle/[0-9a-f]{12}\.js", u.split("?")[0])]
    assert len(bundle) == 1, requested
    code = requests.get(live_server.url + bundle[0], timeout=5).text
    source_map = requests.get(live_server.url + "/static/js/bundle/" + re.search(r"sourceMappingURL=(\S+)", code)[1],
                              timeout=5).json()
    return {os.path.normpath(os.path.join("js/bundle", source)) for source in source_map["sources"]}


def test_the_page_opens_one_stream_for_its_cards_channels_and_no_video_without_a_camera(live_server, browser):
    doc = {"version": 1, "name": "Drive only", "cards": [
        {"type": "drive", "x": 0, "y": 0, "w": 6, "h": 6}, {"type": "robot", "x": 6, "y": 0, "w": 6, "h": 3}]}
    made = requests.post(live_server.url + "/api/layouts", json=doc, timeout=5)
    assert made.status_code == 201, made.text
    choose(live_server, "Drive only")
    context, page = open_dashboard(browser, live_server, DESKTOP)
    try:
        page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
        streams = [u for u in page.requested if u.startswith("/api/events")]
        assert len(streams) == 1, streams
        channels = set(streams[0].split("channels=")[1].split("&")[0].split(","))
        assert channels == {"status", "teleop", "odom", "battery"} | ALWAYS
        assert not [u for u in page.requested if u.startswith(VIDEO_PATHS)]
        assert not [u for u in page.requested if "maplibre" in u or "uPlot" in u]
        assert "js/camera/camera.js" not in page_modules(live_server, page.requested)
        assert "js/teleop/teleop.js" in page_modules(live_server, page.requested)
        check_clean(page)
    finally:
        context.close()

    choose(live_server, "Boat")  # a camera card: its script runs and asks for the topic it shows
    context, page = open_dashboard(browser, live_server, DESKTOP)
    try:
        assert "js/camera/camera.js" in page_modules(live_server, page.requested)
        # It ran: it shows the topic it looks for (no camera in this graph: it says it waits for it).
        page.wait_for_function("() => /image/.test(document.getElementById('camera-message').textContent)",
                               timeout=10000)
        streams = [u for u in page.requested if u.startswith("/api/events")]
        channels = set(streams[0].split("channels=")[1].split("&")[0].split(","))
        assert "light_sequence" in channels and "diagnostics" not in channels and "pose" not in channels
    finally:
        context.close()


def test_plot_echo_and_logs_cards_follow_the_simulator(live_server, browser, sim_process):
    sim_process()
    doc = {"version": 1, "name": "Observe", "cards": [
        {"type": "plot", "x": 0, "y": 0, "w": 6, "h": 4,
         "settings": {"series": [{"topic": "/odom", "field": "twist.twist.angular.z"}], "window_s": 30}},
        {"type": "echo", "x": 6, "y": 0, "w": 6, "h": 4, "settings": {"topic": "/odom"}},
        {"type": "logs", "x": 0, "y": 4, "w": 6, "h": 4, "settings": {"level": "DEBUG", "lines": 8}},
        {"type": "link", "x": 6, "y": 4, "w": 6, "h": 3}]}
    assert requests.post(live_server.url + "/api/layouts", json=doc, timeout=5).status_code == 201
    choose(live_server, "Observe")
    context, page = open_dashboard(browser, live_server, DESKTOP)
    try:
        page.wait_for_selector("[data-card='plot'] .plot-card-chart:not([data-points='0']) canvas", timeout=20000)
        page.wait_for_selector("[data-card='echo'] .echo-card-msg:has-text('twist')", timeout=20000)
        assert page.locator("[data-card='echo'] .echo-card-type").inner_text() == "nav_msgs/msg/Odometry"
        page.wait_for_selector("[data-card='logs'] .logs-card-lines li[data-level]", timeout=20000)
        assert page.locator("[data-card='logs'] .logs-card-lines li").count() <= 8
        page.wait_for_selector("#link-plot canvas", timeout=10000)
        streams = [u for u in page.requested if u.startswith("/api/events")]
        channels = set(streams[0].split("channels=")[1].split("&")[0].split(","))
        assert channels == {"status", "plot", "rosout"} | ALWAYS
        check_clean(page)
    finally:
        context.close()
