"""`flask tiles import` with real files made here: an MBTiles (SQLite, MBTiles 1.3 schema, rows in TMS
order) into a folder and into an MBTiles store, and a GeoJSON drawn basemap; bad files change
nothing. Then the app serves what was imported, on a machine without ROS."""

import json
import re
import sqlite3

import pytest

from tests.integration.basemap.test_fetch import flask_cli, no_ros_env  # noqa: F401 - a fixture
from tests.support.waypoint_helpers import tile_png

# z, x, y (XYZ) around Nathan Benderson Park
TILES = [(14, 4439, 6895), (14, 4440, 6895), (14, 4439, 6896), (15, 8879, 13791)]


def make_mbtiles(path, tiles=TILES, fmt="png", data_of=None, schema="plain", attribution="© another team"):
    """An MBTiles 1.3 file as another tool writes it; `schema="views"` stores tiles as mbutil's
    deduplicated map/images tables behind a `tiles` view."""
    conn = sqlite3.connect(path)
    conn.execute("CREATE TABLE metadata (name TEXT, value TEXT)")
    conn.executemany("INSERT INTO metadata VALUES (?, ?)", [
        ("name", "team basemap"), ("format", fmt), ("attribution", attribution), ("type", "baselayer"),
        ("version", "1.3"), ("minzoom", "14"), ("maxzoom", "15")])
    rows = [(z, x, (1 << z) - 1 - y, (data_of or tile_png)(z, x, y)) for z, x, y in tiles]
    if schema == "views":
        conn.execute("CREATE TABLE map (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_id TEXT)")
        conn.execute("CREATE TABLE images (tile_data BLOB, tile_id TEXT)")
        for i, (z, x, row, data) in enumerate(rows):
            conn.execute("INSERT INTO map VALUES (?, ?, ?, ?)", (z, x, row, f"t{i}"))
            conn.execute("INSERT INTO images VALUES (?, ?)", (data, f"t{i}"))
        conn.execute("CREATE VIEW tiles AS SELECT map.zoom_level AS zoom_level, map.tile_column AS tile_column, "
                     "map.tile_row AS tile_row, images.tile_data AS tile_data FROM map JOIN images "
                     "ON images.tile_id = map.tile_id")
    else:
        conn.execute("CREATE TABLE tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, "
                     "tile_data BLOB)")
        conn.executemany("INSERT INTO tiles VALUES (?, ?, ?, ?)", rows)
    conn.commit()
    conn.close()
    return path


@pytest.mark.parametrize("store_name,schema", [("tiles", "plain"), ("store.mbtiles", "views")])
def test_an_mbtiles_file_is_imported_and_served_with_y_flipped_right(no_ros_env, tmp_path, app_factory,  # noqa: F811
                                                                      store_name, schema):
    source = make_mbtiles(tmp_path / "team.mbtiles", schema=schema)
    store = tmp_path / store_name
    run = flask_cli(no_ros_env, "tiles", "import", str(source), "--out", str(store))
    assert run.returncode == 0, run.stdout + run.stderr
    assert "done: 4 tiles imported, 0 already there" in run.stdout
    client = app_factory(ROVER_WEB_MAP_TILES=str(store)).test_client()
    for z, x, y in TILES:
        response = client.get(f"/tiles/{z}/{x}/{y}")
        assert response.status_code == 200 and response.data == tile_png(z, x, y), (z, x, y)
    z, x, y = TILES[0]
    assert client.get(f"/tiles/{z}/{x}/{(1 << z) - 1 - y}").status_code == 404  # the TMS row is not an XYZ one
    page = client.get("/").get_data(as_text=True)
    basemap = json.loads(re.search(r"data-config='(.*?)'", page).group(1))["basemap"]
    assert basemap["attribution"] == "© another team"
    assert (basemap["minzoom"], basemap["maxzoom"]) == (14, 15)
    west, south, east, north = basemap["bounds"]
    assert west < -82.45 < east and south < 27.374 < north and east - west < 0.1

    again = flask_cli(no_ros_env, "tiles", "import", str(source), "--out", str(store))
    assert again.returncode == 0 and "0 tiles imported, 4 already there" in again.stdout
    forced = flask_cli(no_ros_env, "tiles", "import", str(source), "--out", str(store), "--force",
                       "--attribution", "© ours")
    assert forced.returncode == 0 and "4 tiles imported" in forced.stdout
    info = flask_cli(dict(no_ros_env, ROVER_WEB_MAP_TILES=str(store)), "tiles", "info")
    assert "zoom 14-15" in info.stdout and "'© ours'" in info.stdout


def broken(kind, tmp_path):
    path = tmp_path / "bad.mbtiles"
    if kind == "not sqlite":
        path.write_bytes(b"<html>404</html>" * 10)
    elif kind == "no tiles table":
        conn = sqlite3.connect(path)
        conn.execute("CREATE TABLE metadata (name TEXT, value TEXT)")
        conn.commit()
        conn.close()
    elif kind == "vector tiles":
        make_mbtiles(path, fmt="pbf", data_of=lambda z, x, y: b"\x1a\x00vector")
    elif kind == "one tile is html":
        make_mbtiles(path, data_of=lambda z, x, y: b"<html>oops</html>" if x == 4440 else tile_png(z, x, y))
    elif kind == "off the grid":
        make_mbtiles(path, tiles=TILES + [(3, 9, 0)])
    elif kind == "empty":
        make_mbtiles(path, tiles=[])
    return path


@pytest.mark.parametrize("kind,message", [
    ("not sqlite", "not an MBTiles file"), ("no tiles table", "no 'tiles' table"),
    ("vector tiles", "vector tiles"), ("one tile is html", "not a PNG, JPEG or WebP image"),
    ("off the grid", "not on the tile grid"), ("empty", "has no tiles")])
def test_a_bad_mbtiles_file_is_refused_with_the_reason_and_nothing_is_written(no_ros_env, tmp_path,  # noqa: F811
                                                                             kind, message):
    store = tmp_path / "store.mbtiles"
    run = flask_cli(no_ros_env, "tiles", "import", str(broken(kind, tmp_path)), "--out", str(store))
    assert run.returncode == 1, run.stdout + run.stderr
    assert message in run.stderr and "Traceback" not in run.stderr
    if store.exists():  # opened for writing: created empty, never filled
        conn = sqlite3.connect(store)
        assert conn.execute("SELECT count(*) FROM tiles").fetchone()[0] == 0
        conn.close()


LAKE = {"type": "FeatureCollection", "attribution": "© survey team", "features": [
    {"type": "Feature", "properties": {"kind": "water", "name": "pond"},
     "geometry": {"type": "Polygon", "coordinates": [[[-82.46, 27.37], [-82.44, 27.37], [-82.44, 27.38],
                                                      [-82.46, 27.38], [-82.46, 27.37]]]}},
    {"type": "Feature", "properties": {"kind": "path"},
     "geometry": {"type": "LineString", "coordinates": [[-82.46, 27.369], [-82.44, 27.369, 3.0]]}}]}


def test_a_geojson_file_is_imported_and_served_as_a_drawn_basemap(no_ros_env, tmp_path, app_factory):  # noqa: F811
    source = tmp_path / "Team Lake.geojson"
    source.write_text(json.dumps(LAKE))
    folder = tmp_path / "drawn"
    env = dict(no_ros_env, ROVER_WEB_MAP_GEOJSON_DIR=str(folder))
    run = flask_cli(env, "tiles", "import", str(source))
    assert run.returncode == 0, run.stdout + run.stderr
    assert (folder / "Team-Lake.geojson").is_file() and not list(folder.glob("*.part"))
    again = flask_cli(env, "tiles", "import", str(source))
    assert again.returncode == 1 and "--force" in again.stderr
    assert flask_cli(env, "tiles", "import", str(source), "--name", "lake", "--attribution", "© us").returncode == 0
    info = flask_cli(env, "tiles", "info")
    assert "drawn basemap lake" in info.stdout and "2 features" in info.stdout

    client = app_factory(ROVER_WEB_MAP_GEOJSON_DIR=str(folder)).test_client()
    page = client.get("/").get_data(as_text=True)
    features = json.loads(re.search(r"data-config='(.*?)'", page).group(1))["features"]
    assert [(f["name"], f["url"], f["attribution"]) for f in features] == [
        ("Team-Lake", "/basemap/Team-Lake", "© survey team"), ("lake", "/basemap/lake", "© us")]
    assert features[0]["bounds"] == [-82.46, 27.369, -82.44, 27.38]
    served = client.get("/basemap/lake")
    assert served.status_code == 200 and served.mimetype == "application/geo+json"
    assert served.json["features"] == LAKE["features"]
    missing = client.get("/basemap/nosuch")
    assert missing.status_code == 404 and missing.json["error"] == "unknown_basemap"
    for name in ("..%2F..%2Fetc%2Fpasswd", "lake.geojson", "lake%00", "..", "%2E%2E%2Flake", "lake.geojson%00"):
        response = client.get(f"/basemap/{name}")
        assert response.status_code == 404 and b"root:" not in response.data, name
    # A file broken by hand after the import is left out of the page and never served.
    (folder / "lake.geojson").write_text('{"type": "FeatureCollection", "features": [')
    assert client.get("/basemap/lake").status_code == 404
    page = client.get("/").get_data(as_text=True)
    assert [f["name"] for f in json.loads(re.search(r"data-config='(.*?)'", page).group(1))["features"]] == [
        "Team-Lake"]


def bad_geojson(kind):
    feature = json.loads(json.dumps(LAKE["features"][0]))
    if kind == "nan":
        return '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"kind": "water"}, ' \
               '"geometry": {"type": "Point", "coordinates": [NaN, 27.0]}}]}'
    if kind == "latitude":
        feature["geometry"]["coordinates"][0][1] = [-82.44, 97.0]
    elif kind == "kind":
        feature["properties"]["kind"] = "lava"
    elif kind == "geometry":
        feature["geometry"]["type"] = "Circle"
    elif kind == "not a collection":
        return json.dumps(feature)
    return json.dumps({"type": "FeatureCollection", "features": [feature]})


@pytest.mark.parametrize("kind,message", [
    ("nan", "NaN is not allowed"), ("latitude", "features[0].geometry.coordinates[0][1]"),
    ("kind", "features[0].properties.kind must be one of"), ("geometry", "geometry.type must be one of"),
    ("not a collection", "FeatureCollection")])
def test_a_bad_geojson_file_is_refused_with_where_and_nothing_is_written(no_ros_env, tmp_path,  # noqa: F811
                                                                         kind, message):
    source = tmp_path / "bad.geojson"
    source.write_text(bad_geojson(kind))
    folder = tmp_path / "drawn"
    run = flask_cli(dict(no_ros_env, ROVER_WEB_MAP_GEOJSON_DIR=str(folder)), "tiles", "import", str(source))
    assert run.returncode == 1 and message in run.stderr, run.stderr
    assert not folder.exists() or not list(folder.iterdir())


def test_the_demo_basemap_ships_checked_with_its_attribution(client):
    page = client.get("/").get_data(as_text=True)
    features = json.loads(re.search(r"data-config='(.*?)'", page).group(1))["features"]
    assert [f["name"] for f in features] == ["benderson_park"]
    assert "schematic" in features[0]["attribution"]
    demo = client.get(features[0]["url"]).json
    assert demo["license"] == "MIT" and {f["properties"]["kind"] for f in demo["features"]} >= {"water", "land"}
