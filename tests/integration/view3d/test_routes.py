"""The 3D view's routes with an app in this process: the model from a URDF file, a bad one answered with
its line, meshes served only from inside a package's share folder and cached as immutable, the cloud
route's bounds, and the role each route needs."""

import pytest

from tests.support.auth import bearer
from tests.support.view3d_support import BAD_URDF, BAD_URDF_LINE, ROBOT_URDF, ament_prefix, stl_box


@pytest.fixture
def prefix(tmp_path, monkeypatch):
    found = ament_prefix(tmp_path)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(found))
    return found


@pytest.fixture
def urdf_file(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(ROBOT_URDF)
    return path


def test_robot_from_a_file(app_factory, urdf_file):
    client = app_factory(ROVER_WEB_URDF_FILE=str(urdf_file)).test_client()
    robot = client.get("/api/3d/robot").get_json()
    assert robot["state"] == "ok"
    assert robot["name"] == "testbot" and robot["root"] == "base_link"
    assert robot["links"] == ["base_link", "arm", "mast"]
    assert {"name": "arm_joint", "type": "revolute", "parent": "base_link", "child": "arm"} in robot["joints"]
    assert robot["meshes"] == [{"uri": "package://testbot_description/meshes/mast.stl",
                                "url": "api/3d/mesh/testbot_description/meshes/mast.stl"}]
    assert robot["urdf"] == ROBOT_URDF
    page = client.get("/3d")
    assert page.status_code == 200 and b'id="view3d"' in page.data


def test_a_bad_urdf_is_answered_with_its_line(app_factory, tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(BAD_URDF)
    robot = app_factory(ROVER_WEB_URDF_FILE=str(path)).test_client().get("/api/3d/robot").get_json()
    assert robot["state"] == "error"
    assert robot["error"]["line"] == BAD_URDF_LINE
    assert robot["error"]["message"].startswith(f"line {BAD_URDF_LINE}: ")
    assert "zero" in robot["error"]["message"]


def test_a_missing_file_is_said(app_factory, tmp_path):
    robot = app_factory(ROVER_WEB_URDF_FILE=str(tmp_path / "none.urdf")).test_client().get("/api/3d/robot").get_json()
    assert robot["state"] == "error" and "cannot read" in robot["error"]["message"]


def test_a_mesh_from_the_package_share_is_served_immutable(app, prefix):
    client = app.test_client()
    reply = client.get("/api/3d/mesh/testbot_description/meshes/mast.stl")
    assert reply.status_code == 200
    assert reply.data == stl_box()
    assert reply.headers["Cache-Control"] == "public, max-age=31536000, immutable"
    assert reply.mimetype == "model/stl"
    reply.close()
    etag = reply.headers["ETag"]
    again = client.get("/api/3d/mesh/testbot_description/meshes/mast.stl", headers={"If-None-Match": etag})
    assert again.status_code == 304 and again.data == b""


@pytest.mark.parametrize("path, status, code", [
    ("/api/3d/mesh/testbot_description/meshes/escape.stl", 403, "outside_package"),  # a symlink out of the share
    ("/api/3d/mesh/testbot_description/meshes/%2e%2e/%2e%2e/%2e%2e/secret.stl", 403, "outside_package"),
    ("/api/3d/mesh/testbot_description/meshes//mast.stl", 403, "outside_package"),
    ("/api/3d/mesh/testbot_description/meshes/none.stl", 404, "no_such_mesh"),
    ("/api/3d/mesh/testbot_description/meshes", 415, "not_a_mesh"),
    ("/api/3d/mesh/other_package/meshes/mast.stl", 404, "unknown_package"),
    ("/api/3d/mesh/bad-name/meshes/mast.stl", 400, "bad_package"),
    ("/api/3d/mesh/testbot_description/meshes/mast.stl%00.stl", 400, "bad_mesh_path"),
])
def test_a_mesh_path_that_leaves_the_share_is_refused(app, prefix, path, status, code):
    reply = app.test_client().get(path)
    assert reply.status_code == status, reply.get_json()
    assert reply.get_json()["error"] == code
    assert stl_box(0.3) not in reply.data


def test_the_cloud_route_bounds(app_factory):
    client = app_factory().test_client()
    assert client.get("/api/3d/cloud").get_json()["error"] == "no_cloud_topic"
    client = app_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points").test_client()
    for query, code in (("after=-1", "bad_after"), ("after=x", "bad_after"), ("wait=3", "bad_wait"),
                        ("wait=nan", "bad_wait"), ("wait=-1", "bad_wait")):
        reply = client.get(f"/api/3d/cloud?{query}")
        assert reply.status_code == 400 and reply.get_json()["error"] == code, query
    reply = client.get("/api/3d/cloud?wait=0.2")
    assert reply.status_code == 204 and reply.headers["X-Cloud-Seq"] == "0"


@pytest.mark.parametrize("path", ["/3d", "/api/3d/robot", "/api/3d/mesh/testbot_description/meshes/mast.stl",
                                  "/api/3d/cloud"])
def test_every_route_needs_a_viewer(signed_server_factory, prefix, path):
    import requests

    server = signed_server_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points")
    anonymous = requests.get(server.url + path, timeout=5, allow_redirects=False,
                             headers={"Accept": "application/json"})
    assert anonymous.status_code == 401
    seen = requests.get(server.url + path, timeout=10, headers=bearer(server, "viewer"))
    assert seen.status_code in (200, 204), seen.text


def test_a_waiting_cloud_request_ends_when_its_token_is_revoked(signed_server_factory):
    import threading
    import time

    import requests

    server = signed_server_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points")
    admin = bearer(server, "admin")
    tokens = requests.get(server.url + "/api/tokens", headers=admin, timeout=5).json()["tokens"]
    viewer_token = next(t["id"] for t in tokens if t["user"] == "viewer")
    answer = {}

    def wait():
        t0 = time.monotonic()
        reply = requests.get(server.url + "/api/3d/cloud", params={"wait": 2}, headers=bearer(server, "viewer"),
                             timeout=10)
        answer.update(status=reply.status_code, error=reply.json().get("error"), after_s=time.monotonic() - t0)
    waiter = threading.Thread(target=wait)
    waiter.start()
    time.sleep(0.5)
    assert requests.delete(f"{server.url}/api/tokens/{viewer_token}", headers=admin, timeout=5).ok
    waiter.join(10)
    assert answer["status"] == 401 and answer["error"] == "revoked"
    assert answer["after_s"] < 1.5  # ended by the revocation, not by its 2 s wait
