"""The layout editor in Chromium, the policy enforced: drag and resize on a desktop (1400×1000), the
list on a phone (390×844), settings, undo, and the saved layout as the server stores and renders it."""

import json
import os
import time
from pathlib import Path

import pytest
import requests

from rover_web.layouts.cards import catalogue
from tests.browser.test_layouts import DESKTOP, PHONE, check_always_there, check_clean, choose, open_dashboard

pytestmark = pytest.mark.browser

DOC_SHOT = Path(__file__).resolve().parents[2] / "docs" / "img" / "dashboard-boat.png"
START = {"version": 1, "name": "Start", "cards": [
    {"type": "drive", "x": 0, "y": 0, "w": 4, "h": 6}, {"type": "robot", "x": 4, "y": 0, "w": 4, "h": 3}]}


def stored(server) -> dict:
    mine = requests.get(server.url + "/api/me/layout", timeout=5).json()
    return requests.get(f"{server.url}/api/layouts/{mine['id']}", timeout=5).json()


def start_editing(browser, server, viewport):
    made = requests.post(server.url + "/api/layouts", json=START, timeout=5)
    assert made.status_code == 201, made.text
    choose(server, "Start")
    context, page = open_dashboard(browser, server, viewport)
    page.on("dialog", lambda d: d.accept())
    page.click("#layout-edit")
    view = "grid" if viewport == DESKTOP else "list"
    page.wait_for_selector(f"#layout-editor[data-view='{view}']", timeout=10000)
    assert page.locator("#layout").is_hidden()
    return context, page


def drag(page, selector, dx, dy):
    box = page.locator(selector).bounding_box()
    x, y = box["x"] + 20, box["y"] + 12
    page.mouse.move(x, y)
    page.mouse.down()
    for i in range(1, 11):
        page.mouse.move(x + dx * i / 10, y + dy * i / 10)
    page.mouse.up()


def test_on_a_desktop_cards_are_dragged_resized_added_set_up_undone_and_saved(live_server, browser):
    context, page = start_editing(browser, live_server, DESKTOP)
    try:
        robot = "#editor-grid .grid-stack-item:has([data-card='robot'])"
        page.wait_for_selector(robot)
        column = page.locator("#editor-grid").bounding_box()["width"] / 12
        drag(page, robot, 4 * column, 0)  # four columns right: x 4 -> 8
        page.wait_for_selector(f"{robot}[gs-x='8']", timeout=5000)
        # gridstack shows a card's resize handle while the pointer is over the card.
        handle = page.locator(f"{robot} .ui-resizable-se")
        page.hover(robot)
        handle.wait_for(state="visible", timeout=5000)
        hb = handle.bounding_box()
        page.mouse.move(hb["x"] + hb["width"] / 2, hb["y"] + hb["height"] / 2)
        page.mouse.down()
        for i in range(1, 11):
            page.mouse.move(hb["x"] + hb["width"] / 2, hb["y"] + hb["height"] / 2 + 2 * 60 * i / 10)
        page.mouse.up()
        page.wait_for_selector(f"{robot}[gs-h='5']", timeout=5000)
        # A camera with a topic of its own, then a second camera the editor refuses.
        page.select_option("#editor-add", "camera")
        camera = "#editor-grid .grid-stack-item:has([data-card='camera'])"
        page.wait_for_selector(camera)
        page.click(f"{camera} button:text('Settings')")
        page.fill("#editor-settings [data-setting='topic']", "/front/image_raw")
        page.click("#editor-settings-apply")
        page.wait_for_selector(f"{camera} :text('/front/image_raw')")
        page.select_option("#editor-add", "camera")
        assert "one is the most" in page.locator("#editor-message").inner_text()
        # Undo takes back the last change only: the camera's topic, not the camera.
        page.click("#editor-undo")
        page.wait_for_selector(f"{camera}:not(:has(:text('/front/image_raw')))")
        assert page.locator(camera).count() == 1
        page.fill("#editor-name", "Boat crew")
        page.locator("#editor-name").dispatch_event("change")
        with page.expect_navigation():
            page.click("#editor-save")
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        saved = stored(live_server)
        assert saved["name"] == "Boat crew"
        cards = {c["type"]: c for c in saved["cards"]}
        assert (cards["robot"]["x"], cards["robot"]["w"], cards["robot"]["h"]) == (8, 4, 5)
        assert cards["camera"]["settings"] == {} and cards["camera"]["y"] >= 5
        assert [c["type"] for c in saved["cards"]] == ["drive", "robot", "camera"]  # reading order
        assert page.locator("#layout > [data-card]").evaluate_all("els => els.map(e => e.dataset.card)") == \
            ["drive", "robot", "camera"]
        assert page.locator("#layout > [data-card='robot']").get_attribute("data-x") == "8"
        check_always_there(page, DESKTOP)
        check_clean(page)
    finally:
        context.close()


def test_a_bad_save_says_why_and_keeps_the_edits(live_server, browser):
    context, page = start_editing(browser, live_server, DESKTOP)
    try:
        page.select_option("#editor-add", "echo")  # an echo card needs a topic
        page.wait_for_selector("#editor-grid [data-card='echo']")
        page.click("#editor-save")
        page.wait_for_selector("#editor-message[data-failed='yes']")
        assert "cards[2].settings.topic" in page.locator("#editor-message").inner_text()
        assert stored(live_server)["cards"] == [{**c, "settings": {}} for c in START["cards"]]
        assert page.locator("#editor-grid [data-card='echo']").count() == 1
    finally:
        context.close()


def test_on_a_phone_the_list_editor_moves_removes_and_adds(live_server, browser):
    context, page = start_editing(browser, live_server, PHONE)
    try:
        items = "#editor-list > li"
        assert page.locator(items).evaluate_all("els => els.map(e => e.querySelector('[data-card]').dataset.card)") \
            == ["drive", "robot"]
        page.click(f"{items}:has([data-card='robot']) button:text('Up')")
        page.select_option("#editor-add", "scan_the_code")
        page.click(f"{items}:has([data-card='drive']) button:text('Remove')")
        page.wait_for_selector(f"{items}:has([data-card='scan_the_code'])")
        assert page.locator(items).evaluate_all("els => els.map(e => e.querySelector('[data-card]').dataset.card)") \
            == ["robot", "scan_the_code"]
        overflow = page.evaluate("document.documentElement.scrollWidth - document.documentElement.clientWidth")
        assert overflow <= 0
        with page.expect_navigation():
            page.click("#editor-save")
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        assert [c["type"] for c in stored(live_server)["cards"]] == ["robot", "scan_the_code"]
        assert page.locator("#layout > [data-card]").evaluate_all("els => els.map(e => e.dataset.card)") == \
            ["robot", "scan_the_code"]
        check_always_there(page, PHONE)
        check_clean(page)
    finally:
        context.close()


def test_an_exported_layout_imported_in_the_editor_becomes_the_users_layout(live_server, browser, tmp_path):
    context, page = start_editing(browser, live_server, DESKTOP)
    try:
        boat = choose(live_server, "Boat")
        exported = tmp_path / "boat.json"
        exported.write_text(json.dumps({**boat, "name": "Boat copy"}))  # an export, renamed
        with page.expect_navigation():
            page.set_input_files("#editor-import", str(exported))
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        assert stored(live_server) == {**boat, "name": "Boat copy"}
        assert page.locator("#layout > [data-card]").evaluate_all("els => els.map(e => e.dataset.card)") == \
            [c["type"] for c in boat["cards"]]
    finally:
        context.close()


def test_viewers_get_no_editor_and_the_server_refuses_them(signed_server, browser):
    context = browser.new_context(viewport=DESKTOP)
    try:
        page = context.new_page()
        page.goto(signed_server.url + "/login")
        page.fill("input[name=username]", "viewer")
        page.fill("input[name=password]", "correct horse battery")
        page.click("button[type=submit]")
        page.wait_for_selector("#layout-select")
        assert page.locator("#layout-edit").count() == 0 and page.locator("#layout-editor").count() == 0
        refused = page.request.post(signed_server.url + "/api/layouts", data=START)
        assert refused.status == 403
    finally:
        context.close()


def test_a_first_time_user_builds_a_boat_dashboard(live_server, browser, sim_process, tmp_path):
    """docs/dashboards.md's steps, as a new operator takes them; the screenshot there comes from here
    (UPDATE_DOC_SCREENSHOTS=1 writes docs/img/dashboard-boat.png)."""
    sim_process()
    context, page = start_editing(browser, live_server, DESKTOP)
    try:
        started = time.monotonic()
        page.click("#editor-clear")
        page.fill("#editor-name", "My boat")
        page.locator("#editor-name").dispatch_event("change")
        for card in ("camera", "scan_the_code", "gps_map", "drive"):  # each fills the first free place
            page.select_option("#editor-add", card)
        stc = "#editor-grid .grid-stack-item:has([data-card='scan_the_code'])"
        page.wait_for_selector(f"{stc}[gs-x='6'][gs-y='0']")  # beside the camera
        page.wait_for_selector("#editor-grid .grid-stack-item:has([data-card='drive'])[gs-x='8'][gs-y='6']")
        with page.expect_navigation():
            page.click("#editor-save-new")
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        took_s = time.monotonic() - started
        saved = stored(live_server)
        assert saved["name"] == "My boat"
        assert sorted(c["type"] for c in saved["cards"]) == ["camera", "drive", "gps_map", "scan_the_code"]
        page.wait_for_selector("#camera-image[src*='stream'], #camera-video:not([hidden])", timeout=15000)
        page.wait_for_selector(".maplibregl-canvas", timeout=15000)
        page.wait_for_selector("#scan-the-code .stc-box", timeout=15000)
        page.wait_for_timeout(1500)  # a few frames and light changes
        check_always_there(page, DESKTOP)
        check_clean(page)
        shot = DOC_SHOT if os.environ.get("UPDATE_DOC_SCREENSHOTS") == "1" else tmp_path / "dashboard-boat.png"
        page.screenshot(path=str(shot), full_page=False)
        print(f"\nbuilt the boat dashboard in {took_s:.1f} s of scripted steps; screenshot {shot}")
    finally:
        context.close()


MODEL = """async ([doc, types]) => {
    const { LayoutModel } = await import('/static/js/dashboard/editor/model.js');
    const m = new LayoutModel(doc, types);
    const cells = () => m.cards.map((c) => [c.type, c.x, c.y, c.w, c.h]);
    const steps = {};
    m.add('camera'); m.add('scan_the_code'); m.add('gps_map');
    steps.added = cells();
    steps.second_camera = m.add('camera');
    m.place({ [m.cards.find((c) => c.type === 'scan_the_code').k]: { x: 8, y: 20, w: 4, h: 6 } });
    steps.placed = cells();
    m.undo();
    steps.undone = cells();
    m.shift(m.cards[0].k, 1);
    steps.shifted = cells().map((c) => c[0]);
    steps.doc = m.toDoc();
    return steps;
}"""


def test_the_editors_model_places_refuses_undoes_and_saves_what_the_server_accepts(live_server, page):
    types = catalogue()  # what the page embeds for the editor
    page.goto(live_server.url + "/static/js/core/api.js")  # same origin, no page script
    empty = {"version": 1, "name": "Model", "cards": []}
    steps = page.evaluate(MODEL, [empty, types])
    assert steps["added"] == [["camera", 0, 0, 6, 6], ["scan_the_code", 6, 0, 4, 6], ["gps_map", 0, 6, 8, 7]]
    assert steps["second_camera"] is None
    assert steps["placed"][-1] == ["scan_the_code", 8, 20, 4, 6]  # reading order: now last
    assert steps["undone"] == steps["added"]
    assert steps["shifted"] == ["scan_the_code", "camera", "gps_map"]
    saved = requests.post(live_server.url + "/api/layouts", json=steps["doc"], timeout=5)
    assert saved.status_code == 201, saved.text
