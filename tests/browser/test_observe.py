"""Logs, diagnostics and plots in Chromium: the logs page filters and pauses, the plot page draws a series
from the simulator and exports it as CSV and says beside the field chooser why a camera's images are
not plotted, the dashboard shows diagnostics and the link plot."""

import csv
import io

import pytest
import requests

from tests.support.camera_peer import ImagePublisher

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def rows(page):
    return page.eval_on_selector_all("#log-body tr", "trs => trs.map(tr => [...tr.cells].map(c => c.textContent))")


def test_the_logs_page_filters_groups_and_pauses(live_server, ros_peer, page):
    peer = ros_peer("browser_log_node")
    other = ros_peer("quiet_node")
    peer.log("all nominal", "info")
    peer.log("wheel slip", "warning", times=3)
    peer.log("motor fault", "error")
    other.log("other node speaks", "error")
    page.goto(live_server.url + "/logs")
    page.wait_for_function("document.querySelector('#log-body').textContent.includes('other node speaks')",
                           timeout=15000)
    page.wait_for_function("document.querySelector('#log-body').textContent.includes('motor fault')", timeout=15000)
    shown = {r[3]: r for r in rows(page)}
    assert shown["wheel slip"][1] == "WARN" and shown["wheel slip"][4] == "3"  # grouped with its count
    assert "all nominal" in shown

    page.select_option("#log-level", "ERROR")  # a minimum: ERROR and FATAL
    page.wait_for_function("!document.querySelector('#log-body').textContent.includes('wheel slip')")
    assert sorted(r[3] for r in rows(page)) == ["motor fault", "other node speaks"]
    page.fill("#log-node", "browser_log")
    page.wait_for_function("!document.querySelector('#log-body').textContent.includes('other node speaks')")
    assert [r[3] for r in rows(page)] == ["motor fault"]
    page.fill("#log-node", "")
    page.fill("#log-contains", "OTHER")
    page.wait_for_function("!document.querySelector('#log-body').textContent.includes('motor fault')")
    assert [r[3] for r in rows(page)] == ["other node speaks"]

    # Live lines arrive newest first while live; none while paused; resume catches up.
    page.fill("#log-contains", "")
    page.select_option("#log-level", "DEBUG")
    peer.log("live line one", "info")
    page.wait_for_function("document.querySelector('#log-body tr td:nth-child(4)').textContent === 'live line one'",
                           timeout=10000)
    page.click("#log-pause")
    peer.log("said while paused", "info")
    page.wait_for_function("document.querySelector('#log-state').textContent.includes('new line')", timeout=10000)
    assert "said while paused" not in page.inner_text("#log-body")
    page.click("#log-pause")
    page.wait_for_function("document.querySelector('#log-body tr td:nth-child(4)').textContent === 'said while paused'",
                           timeout=10000)
    # And the health bar counts the errors of the last minute.
    page.wait_for_selector("#link-errors[data-state='errors']", timeout=5000)
    assert int(page.inner_text("#link-errors b")) >= 2
    assert page.watch.console_errors == [] and page.watch.offhost == []


def test_the_plot_page_draws_a_simulator_series_and_exports_csv(live_server, sim_process, page, tmp_path):
    sim_process()
    page.goto(live_server.url + "/plot")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    page.wait_for_selector("#plot-topic option[value='/odom']", state="attached", timeout=15000)
    page.select_option("#plot-topic", "/odom")
    page.wait_for_selector("#plot-fields option[value='twist.twist.linear.x']", state="attached", timeout=10000)
    assert "Nothing plotted yet" in page.locator("#plot-empty").inner_text()  # what to do first
    page.fill("#plot-field", "pose.pose.position.x")
    page.click("#plot-add")
    page.wait_for_selector("#plot-series li[data-series='/odom pose.pose.position.x']", timeout=10000)
    assert page.locator("#plot-empty").is_hidden()
    page.wait_for_function("Number(document.querySelector('#plot-chart').dataset.points) > 20", timeout=15000)
    assert page.locator("#plot-chart canvas").count() == 1
    # A second series on the same time axis.
    page.fill("#plot-field", "twist.twist.angular.z")
    page.click("#plot-add")
    page.wait_for_selector("#plot-series li[data-series='/odom twist.twist.angular.z']", timeout=10000)
    # A field that is not a number is refused with the server's reason.
    page.fill("#plot-field", "header.frame_id")
    page.click("#plot-add")
    page.wait_for_selector("#plot-error:not([hidden])", timeout=5000)
    assert "not a number" in page.inner_text("#plot-error")

    page.click("#plot-pause")
    with page.expect_download() as download:
        page.click("#plot-csv")
    path = tmp_path / "plot.csv"
    download.value.save_as(path)
    table = list(csv.reader(io.StringIO(path.read_text())))
    assert table[0] == ["time_unix_s", "/odom pose.pose.position.x", "/odom twist.twist.angular.z"]
    assert len(table) > 20
    times = [float(r[0]) for r in table[1:]]
    assert times == sorted(times)
    assert all(r[1] == "" or float(r[1]) == float(r[1]) for r in table[1:])
    # The one refused field is the browser's only complaint.
    assert [e for e in page.watch.console_errors if "status of 400" not in e] == []
    assert page.watch.offhost == []


def test_the_plot_page_says_beside_the_field_why_an_image_topic_is_not_plotted(live_server, page):
    topic = "/test/plot_camera"
    camera = ImagePublisher(topic, width=32, height=24, hz=5)
    try:
        page.goto(live_server.url + "/plot")
        page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
        page.wait_for_selector(f"#plot-topic option[value='{topic}']", state="attached", timeout=15000)
        assert page.locator("#plot-refusal").is_hidden()
        page.select_option("#plot-topic", topic)
        page.wait_for_selector("#plot-refusal:not([hidden])", timeout=10000)
        # The server's own words (its 422), beside the field, not a generic failure below the form.
        reply = requests.get(live_server.url + "/api/plot/fields", params={"topic": topic}, timeout=5)
        assert reply.status_code == 422 and reply.json()["error"] == "not_plottable"
        assert page.inner_text("#plot-refusal") == reply.json()["message"]
        assert "sensor_msgs/msg/Image" in page.inner_text("#plot-refusal")
        assert page.get_attribute("#plot-refusal", "data-code") == "not_plottable"
        assert page.get_attribute("#plot-field", "aria-invalid") == "true"
        assert page.locator("#plot-error").is_hidden()
        near = page.evaluate("""() => {
            const a = document.getElementById('plot-field').getBoundingClientRect();
            const b = document.getElementById('plot-refusal').getBoundingClientRect();
            return Math.abs((a.top + a.bottom) / 2 - (b.top + b.bottom) / 2) < 2 * a.height;
        }""")
        assert near  # on the field's row, not somewhere else on the page
        # Adding a field anyway meets the same refusal there, and no series starts.
        page.fill("#plot-field", "height")
        page.evaluate("document.getElementById('plot-refusal').hidden = true")
        page.click("#plot-add")
        page.wait_for_selector("#plot-refusal:not([hidden])", timeout=10000)
        assert "not numbers to plot" in page.inner_text("#plot-refusal")
        assert page.locator("#plot-series li").count() == 0
        # Choosing no topic clears it.
        page.select_option("#plot-topic", "")
        page.wait_for_selector("#plot-refusal", state="hidden", timeout=5000)
        assert page.get_attribute("#plot-field", "aria-invalid") == "false"
        assert [e for e in page.watch.console_errors if "status of 422" not in e] == []
        assert page.watch.offhost == []
    finally:
        camera.close()


def test_the_dashboard_shows_diagnostics_and_the_link_plot(live_server, sim_process, page):
    sim_process()
    page.goto(live_server.url + "/")
    page.wait_for_function("document.querySelector('#diag-hardware').textContent.includes('battery')", timeout=15000)
    hardware = page.inner_text("#diag-hardware")
    assert "motor_controller" in hardware and "gps" in hardware
    page.wait_for_function("Number(document.querySelector('#link-plot').dataset.points) >= 3", timeout=15000)
    assert float(page.get_attribute("#link-plot", "data-rtt-ms")) > 0
    page.wait_for_function("document.querySelector('#link-plot').dataset.ageMs !== ''", timeout=10000)
    assert page.locator("#link-plot canvas").count() == 1
    page.goto(live_server.url + "/diagnostics")
    page.wait_for_function("document.querySelector('#diag-body').textContent.includes('sim_rover: gps')",
                           timeout=10000)
    assert page.watch.console_errors == [] and page.watch.offhost == []


def test_the_status_page_plots_the_round_trip_and_the_robots_newest_message(live_server, sim_process, page):
    sim_process("--only", "rover")
    page.goto(live_server.url + "/status")
    page.wait_for_function("Number(document.querySelector('#link-plot').dataset.points) >= 3", timeout=15000)
    assert float(page.get_attribute("#link-plot", "data-rtt-ms")) > 0
    page.wait_for_function("document.querySelector('#link-plot').dataset.ageMs !== ''", timeout=10000)
    assert page.locator("#link-plot canvas").count() == 1
    page.wait_for_function("document.querySelector('#status-topics').textContent.includes('/odom')", timeout=10000)
    assert page.locator("nav a[aria-current='page']").text_content() == "Status"  # in the bar or its menu
    assert page.watch.console_errors == [] and page.watch.offhost == []
