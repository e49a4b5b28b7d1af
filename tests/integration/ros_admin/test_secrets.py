"""Parameters whose names say they hold a secret (issue 27): hidden below admin, never logged."""

import logging

import pytest
import requests

from tests.integration.ros_admin.conftest import PEER, PEER_URL
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

SECRET = "hunter2"


def parameters(server, role):
    def listed():
        response = requests.get(server.url + PEER_URL + "/parameters", timeout=10,
                                headers={"Authorization": f"Bearer {server.tokens[role]}"})
        return response.status_code == 200 and response
    return wait_until(listed, 15, "the peer's parameters")


@pytest.mark.parametrize("role", ["viewer", "operator"])
def test_below_admin_a_secret_parameter_is_listed_without_its_value(signed_server, admin_peer, role):
    response = parameters(signed_server, role)
    assert SECRET not in response.text
    listed = {p["name"]: p for p in response.json()["parameters"]}
    assert (listed["ntrip_password"]["value"], listed["ntrip_password"]["hidden"]) == (None, True)
    assert (listed["label"]["value"], listed["label"]["hidden"]) == ("hello", False)


def test_an_admin_reads_and_sets_it_and_the_log_never_holds_it(signed_server, admin_peer, caplog):
    admin = {"Authorization": f"Bearer {signed_server.tokens['admin']}"}
    url = signed_server.url
    listed = {p["name"]: p for p in parameters(signed_server, "admin").json()["parameters"]}
    assert (listed["ntrip_password"]["value"], listed["ntrip_password"]["hidden"]) == (SECRET, False)
    caplog.set_level(logging.DEBUG)
    response = requests.put(f"{url}{PEER_URL}/parameters/ntrip_password", json={"value": "s3cret-new"},
                            headers=admin, timeout=10)
    assert response.status_code == 200, response.text
    response = requests.put(f"{url}{PEER_URL}/parameters/ntrip_password", json={"value": ["x-secret-list"]},
                            headers=admin, timeout=10)  # a refusal's message must not carry it either
    assert response.status_code == 400
    # Reading the values through the parameter service: the response is not logged.
    response = requests.post(url + "/api/services/call", headers=admin, timeout=10, json={
        "service": f"{PEER}/get_parameters", "type": "rcl_interfaces/srv/GetParameters",
        "request": {"names": ["ntrip_password"]}})
    assert response.status_code == 200 and "s3cret-new" in response.text
    viewer = {"Authorization": f"Bearer {signed_server.tokens['viewer']}"}
    log = requests.get(url + "/api/ros/log", headers=viewer, timeout=5)
    assert log.status_code == 200
    entries = log.json()["entries"]
    assert [(e["control"], e["value"]) for e in entries[1:3]] == [
        ("set_parameter", "(hidden)"), ("set_parameter", "(hidden)")]
    assert entries[0]["reason"] == "response: (parameter values are not logged)"
    for secret in ("s3cret-new", SECRET, "x-secret-list"):
        assert secret not in log.text
        assert secret not in caplog.text
