"""`flask --app rover_web tiles fetch` against a tile server on 127.0.0.1, then the app serves the
tiles itself with that server gone. The command runs on a machine without ROS: it starts no node."""

import json
import re
import sqlite3
import subprocess
import sys

import pytest

from rover_web.basemap.tile_store import tile_count
from rover_web.config import ROOT
from tests.support.rospeer import subprocess_env
from tests.support.waypoint_helpers import TileServer

BBOX = "-82.462,27.366,-82.438,27.382"  # Nathan Benderson Park
BBOX_TUPLE = (-82.462, 27.366, -82.438, 27.382)


@pytest.fixture
def tile_server():
    server = TileServer(max_zoom=16)
    yield server
    server.stop()


@pytest.fixture
def no_ros_env(tmp_path):
    """An environment where `import rclpy` fails, as on a laptop that only prepares maps."""
    fake = tmp_path / "no_ros" / "rclpy"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('rclpy is deliberately missing in this test')\n")
    env = subprocess_env()
    env["PYTHONPATH"] = f"{fake.parent}:{env['PYTHONPATH']}"
    probe = subprocess.run([sys.executable, "-c", "import rclpy"], env=env, capture_output=True, cwd=ROOT)
    assert probe.returncode != 0  # the fake really hides rclpy
    return env


def flask_cli(env, *args, timeout=120):
    return subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", *args], env=env, cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


def test_fetch_into_a_folder_then_the_app_serves_it_offline(tile_server, no_ros_env, tmp_path, app_factory):
    out = tmp_path / "tiles"
    planned = tile_count(BBOX_TUPLE, 12, 15)
    run = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", BBOX, "--zoom", "12-15", "--url", tile_server.template,
                    "--out", str(out), "--attribution", "© test tiles")
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"done: {planned} fetched, 0 already there, 0 not on the server, 0 failed" in run.stdout
    assert len(tile_server.requests) == planned
    assert len(list(out.rglob("*.png"))) == planned and not list(out.rglob("*.part"))
    meta = json.loads((out / "metadata.json").read_text())
    assert (meta["minzoom"], meta["maxzoom"], meta["bounds"]) == (12, 15, list(BBOX_TUPLE))

    again = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", BBOX, "--zoom", "12-15", "--url", tile_server.template,
                      "--out", str(out))
    assert again.returncode == 0 and f"0 fetched, {planned} already there" in again.stdout
    assert len(tile_server.requests) == planned  # resumable: nothing downloaded twice
    served = dict(tile_server.served)
    tile_server.stop()

    client = app_factory(ROVER_WEB_MAP_TILES=str(out)).test_client()
    for (z, x, y), data in served.items():
        r = client.get(f"/tiles/{z}/{x}/{y}")
        assert r.status_code == 200 and r.mimetype == "image/png" and r.data == data, (z, x, y)
    assert client.get("/tiles/16/0/0").status_code == 404
    assert client.get("/tiles/3/9/0").status_code == 404  # outside the grid
    page = client.get("/").get_data(as_text=True)
    basemap = json.loads(re.search(r"data-config='(.*?)'", page).group(1))["basemap"]
    assert basemap["tiles"] == ["/tiles/{z}/{x}/{y}"] and basemap["attribution"] == "© test tiles"
    assert (basemap["minzoom"], basemap["maxzoom"], basemap["bounds"]) == (12, 15, list(BBOX_TUPLE))


def test_fetch_into_mbtiles_stores_tms_rows_and_the_app_flips_them_back(tile_server, no_ros_env, tmp_path, app_factory):
    out = tmp_path / "park.mbtiles"
    run = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", BBOX, "--zoom", "13-14", "--url", tile_server.template,
                    "--out", str(out))
    assert run.returncode == 0, run.stdout + run.stderr
    conn = sqlite3.connect(out)
    try:
        rows = conn.execute("SELECT zoom_level, tile_column, tile_row FROM tiles").fetchall()
        meta = dict(conn.execute("SELECT name, value FROM metadata"))
    finally:
        conn.close()
    assert sorted(rows) == sorted((z, x, (1 << z) - 1 - y) for z, x, y in tile_server.served)
    assert meta["format"] == "png" and (meta["minzoom"], meta["maxzoom"]) == ("13", "14")
    served = dict(tile_server.served)
    tile_server.stop()
    client = app_factory(ROVER_WEB_MAP_TILES=str(out)).test_client()
    for (z, x, y), data in served.items():
        assert client.get(f"/tiles/{z}/{x}/{y}").data == data


def test_fetch_refuses_too_large_an_area_before_downloading(tile_server, no_ros_env, tmp_path):
    out = tmp_path / "big"
    run = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", "-83,27,-82,28", "--zoom", "10-18",
                    "--url", tile_server.template, "--out", str(out), "--max-tiles", "1000")
    assert run.returncode != 0
    assert "the limit is 1,000" in run.stderr and "smaller --bbox" in run.stderr
    assert tile_server.requests == [] and not out.exists()
    bad = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", "-82,27,-83,28", "--zoom", "12",
                    "--url", tile_server.template, "--out", str(out))
    assert bad.returncode == 2 and "W < E" in bad.stderr


def test_tiles_the_server_does_not_have_are_counted_not_fatal(tile_server, no_ros_env, tmp_path):
    run = flask_cli(no_ros_env, "tiles", "fetch", "--bbox", BBOX, "--zoom", "16-17", "--url", tile_server.template,
                    "--out", str(tmp_path / "t"))
    assert run.returncode == 0, run.stderr
    missing = tile_count(BBOX_TUPLE, 17, 17)
    assert f"{missing} not on the server, 0 failed" in run.stdout


def test_fetch_defaults_to_the_configured_store_and_info_describes_it(tile_server, no_ros_env, tmp_path):
    env = dict(no_ros_env, ROVER_WEB_MAP_TILES=str(tmp_path / "configured"))
    run = flask_cli(env, "tiles", "fetch", "--bbox", BBOX, "--zoom", "12", "--url", tile_server.template)
    assert run.returncode == 0, run.stderr
    assert list((tmp_path / "configured" / "12").rglob("*.png"))
    info = flask_cli(env, "tiles", "info")
    assert info.returncode == 0 and "(folder): zoom 12-12" in info.stdout
