"""rover_web without tf2_msgs (a server process where the package cannot be imported): it runs, /api/tf
says what is missing and how to get it, a lookup is a 503 saying the same, and the TF page says so."""

import pytest
import requests

from rover_web.config import ROOT

pytestmark = pytest.mark.ros

SHIM = ROOT / "tests" / "support" / "no_tf2_msgs"


def test_without_tf2_msgs_the_app_runs_and_says_what_to_install(server_process):
    server = server_process(env={"PYTHONPATH": f"{SHIM}:{ROOT}"}).start()
    tree = requests.get(server.url + "/api/tf", timeout=5).json()
    assert tree["available"] is False and tree["frames"] == {}
    assert "tf2_msgs" in tree["missing"] and "scripts/build_interfaces.sh" in tree["missing"]
    assert "/opt/ros/jazzy" in tree["missing"]
    lookup = requests.get(server.url + "/api/tf/lookup", params={"target": "map", "source": "base_link"}, timeout=5)
    assert lookup.status_code == 503 and lookup.json()["error"] == "tf_unavailable"
    assert "scripts/build_interfaces.sh" in lookup.json()["message"]
    page = requests.get(server.url + "/tf", timeout=5)
    assert page.status_code == 200 and "TF is off" in page.text and "build_interfaces.sh" in page.text
    assert requests.get(server.url + "/api/status", timeout=5).status_code == 200
    assert "Traceback" not in server.log()
