"""The simulator is a robot with a model: its /robot_description reaches the 3D view, whose links
include the sensor frames the simulator's TF places."""

import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros


def test_the_simulator_s_description_reaches_the_3d_view(live_server, sim_process):
    sim_process()
    got = wait_until(lambda: (r := requests.get(live_server.url + "/api/3d/robot", timeout=5).json())["state"] == "ok"
                     and r, 20, "the simulator's description")
    assert got["source"] == "/robot_description" and got["name"] == "sim_rover"
    assert {"base_link", "base_scan", "gps", "camera"} <= set(got["links"])
