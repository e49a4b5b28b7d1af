"""The hub's app in this process (no robot): its routes described, no ROS imported to build it,
and its roles those of a robot (tests/integration/hub/test_hub.py has the hub with real robots)."""

from __future__ import annotations

import json
import re
import socket
import subprocess
import sys

import pytest
from openapi_spec_validator import validate

from rover_web.config import ROOT
from tests.conftest import free_port
from tests.integration.apidocs.test_openapi import described, routes
from tests.support.auth import add_users, bearer


@pytest.fixture
def hub_app(app_factory, tmp_path):
    key = tmp_path / "fleet.key"
    key.write_text("k" * 64)
    key.chmod(0o600)
    db = tmp_path / "hub.sqlite3"
    tokens = add_users(db)
    app = app_factory(ROVER_WEB_HUB=True, ROVER_WEB_ZENOH_MODE="peer", ROVER_WEB_FLEET_KEY_FILE=str(key),
                      ROVER_WEB_ZENOH_LISTEN=[f"tcp/127.0.0.1:{free_port()}"], ROVER_WEB_AUTH="required",
                      ROVER_WEB_DB_PATH=str(db))
    app.tokens = tokens
    return app


def test_every_hub_route_is_described_and_the_document_is_valid(hub_app):
    document = hub_app.test_client().get("/api/openapi.json", headers=bearer(hub_app, "viewer")).get_json()
    assert routes(hub_app) == described(document)
    validate(document)


def test_stop_all_takes_any_signed_in_user_as_on_a_robot(hub_app):
    client = hub_app.test_client()
    assert client.post("/api/estop/all", json={}).status_code == 401
    reply = client.post("/api/estop/all", json={}, headers=bearer(hub_app, "viewer"))
    assert reply.status_code == 200 and reply.json["robots"] == {} and reply.json["engaged"] is False
    refused = client.post("/api/estop/all", json={"engaged": False}, headers=bearer(hub_app, "viewer"))
    assert (refused.status_code, refused.json["error"]) == (400, "release_per_robot")


def test_building_a_hub_imports_no_ros(tmp_path):
    key = tmp_path / "fleet.key"
    key.write_text("k" * 64)
    key.chmod(0o600)
    settings = {"TESTING": True, "ROVER_WEB_HUB": True, "ROVER_WEB_ZENOH_MODE": "peer",
                "ROVER_WEB_FLEET_KEY_FILE": str(key), "ROVER_WEB_ZENOH_LISTEN": [f"tcp/127.0.0.1:{free_port()}"],
                "ROVER_WEB_DB_PATH": str(tmp_path / "hub.sqlite3"), "ROVER_WEB_SECRET_KEY": "x" * 40,
                "ROVER_WEB_HOST": "127.0.0.1"}
    code = (f"import sys; from rover_web import create_app; create_app({settings!r}).extensions['rover_web']"
            ".shutdown(); print(sorted(m for m in sys.modules if m.split('.')[0] == 'rclpy'))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_a_hub_that_cannot_serve_ends_rather_than_hangs(tmp_path):
    # Zenoh's callback threads are not daemons: with the session left open, the interpreter waited
    # for them forever once `flask run` gave up on a port in use.
    from tests.support.rospeer import subprocess_env

    key = tmp_path / "fleet.key"
    key.write_text("k" * 64)
    key.chmod(0o600)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        env = subprocess_env(ROVER_WEB_HUB="true", ROVER_WEB_ZENOH_MODE="peer", ROVER_WEB_FLEET_KEY_FILE=str(key),
                             ROVER_WEB_ZENOH_LISTEN=f"tcp/127.0.0.1:{free_port()}",
                             ROVER_WEB_DB_PATH=str(tmp_path / "hub.sqlite3"))
        proc = subprocess.Popen([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                                 "--port", str(taken.getsockname()[1])], cwd=ROOT, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            assert proc.wait(20) == 1
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)
            output = proc.stdout.read()
            proc.stdout.close()
    assert "is in use" in output


def test_the_hub_page_asks_a_browser_to_sign_in_and_shows_the_robots_after(hub_app):
    from tests.support.auth import sign_in

    client = hub_app.test_client()
    to_login = client.get("/robots")
    assert to_login.status_code == 302 and "/login?next=/robots" in to_login.headers["Location"]
    assert sign_in(client, "viewer").status_code == 303
    assert client.get("/").headers["Location"].endswith("/robots")
    page = client.get("/robots")
    assert page.status_code == 200 and "No robot heard yet." in page.get_data(as_text=True)


def test_the_hub_map_has_the_robots_basemap_and_serves_its_tiles(app_factory, tmp_path):
    """The hub's map is configured from settings alone (no WaypointsService there), as a robot's is."""
    from rover_web.basemap.tile_store import FolderTiles

    key = tmp_path / "fleet.key"
    key.write_text("k" * 64)
    key.chmod(0o600)
    tile, tiles = b"\x89PNG\r\n\x1a\n" + b"\0" * 16, tmp_path / "tiles"
    FolderTiles(tiles).put(12, 1110, 1720, tile, "png")
    FolderTiles(tiles).update_metadata(bounds=[-82.5, 27.3, -82.4, 27.4], minzoom=12, maxzoom=12,
                                       attribution="© test tiles", source="test")
    app = app_factory(ROVER_WEB_HUB=True, ROVER_WEB_ZENOH_MODE="peer", ROVER_WEB_FLEET_KEY_FILE=str(key),
                      ROVER_WEB_ZENOH_LISTEN=[f"tcp/127.0.0.1:{free_port()}"], ROVER_WEB_MAP_TILES=str(tiles),
                      ROVER_WEB_MAP_CENTER_LNG=-82.45, ROVER_WEB_MAP_CENTER_LAT=27.37, ROVER_WEB_MAP_ZOOM=12)
    client = app.test_client()
    page = client.get("/robots").get_data(as_text=True)
    config = json.loads(re.search(r"data-config='(.*?)'", page).group(1))
    assert config["center"] == [-82.45, 27.37] and config["zoom"] == 12
    assert config["basemap"]["tiles"] == ["/tiles/{z}/{x}/{y}"] and config["basemap"]["attribution"] == "© test tiles"
    served = client.get("/tiles/12/1110/1720")
    assert served.status_code == 200 and served.mimetype == "image/png" and served.data == tile
    assert client.get("/tiles/12/0/0").status_code == 404
