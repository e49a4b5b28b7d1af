"""Tile math and the two local stores; MBTiles rows are TMS (y flipped), as every other tool writes them."""

import sqlite3

import click
import pytest

from rover_web.basemap.fetch import TooManyTiles, check_url_template, fetch_tiles, parse_bbox, parse_zoom
from rover_web.basemap.tile_store import (
    FolderTiles,
    MBTiles,
    image_format,
    open_tile_store,
    tile_count,
    tile_ranges,
    tile_x,
    tile_y,
    valid_tile,
)

PNG = b"\x89PNG\r\n\x1a\n" + b"rest"
JPG = b"\xff\xd8\xff\xe0" + b"rest"


def test_tile_math_matches_the_slippy_map_formulas():
    assert (tile_x(-180, 0), tile_y(85, 0)) == (0, 0)
    # Nathan Benderson Park at zoom 14, by the OSM wiki's formula worked by hand:
    # x = (lng + 180) / 360 * 2^14 = 4439.6; y = (1 - ln(tan(lat) + sec(lat)) / pi) / 2 * 2^14 = 6895.6.
    assert (tile_x(-82.4500873, 14), tile_y(27.3742443, 14)) == (4439, 6895)
    assert tile_x(180, 3) == 7 and tile_y(-89, 3) == 7  # edges clamp into the grid
    assert tile_ranges((-1, -1, 1, 1), 1, 1) == [(1, 0, 1, 0, 1)]
    assert tile_count((-1, -1, 1, 1), 0, 2) == 1 + 4 + 4
    assert valid_tile(0, 0, 0) and not valid_tile(2, 4, 0) and not valid_tile(25, 0, 0)


def test_image_format_sniffs_content_not_names():
    assert image_format(PNG) == "png" and image_format(JPG) == "jpg"
    assert image_format(b"RIFF\x00\x00\x00\x00WEBPVP8 ") == "webp"
    assert image_format(b"<html>rate limited</html>") is None


def test_folder_store_reads_writes_and_reports_zooms(tmp_path):
    store = FolderTiles(tmp_path / "tiles")
    assert not store.exists()
    store.put(3, 2, 1, PNG, "png")
    store.put(5, 9, 10, JPG, "jpg")
    assert store.exists()
    assert store.get(3, 2, 1) == (PNG, "png") and store.get(5, 9, 10) == (JPG, "jpg")
    assert store.get(3, 2, 2) is None and store.has(5, 9, 10)
    assert not list((tmp_path / "tiles").rglob("*.part"))
    meta = store.metadata()
    assert (meta["minzoom"], meta["maxzoom"], meta["bounds"]) == (3, 5, None)
    store.update_metadata(bounds=[-1, -1, 1, 1], minzoom=3, maxzoom=5, attribution="© test", source="http://x")
    store.update_metadata(bounds=[0, 0, 2, 2], minzoom=4, maxzoom=6, attribution="", source="http://x")
    meta = store.metadata()
    assert (meta["minzoom"], meta["maxzoom"], meta["bounds"], meta["attribution"]) == (3, 6, [-1, -1, 2, 2], "© test")


def test_mbtiles_written_by_another_tool_is_read_with_y_flipped(tmp_path):
    path = tmp_path / "area.mbtiles"
    conn = sqlite3.connect(path)
    conn.executescript("CREATE TABLE metadata (name text, value text);"
                       "CREATE TABLE tiles (zoom_level integer, tile_column integer, "
                       "tile_row integer, tile_data blob);")
    # XYZ tile z=2, x=1, y=0 (the northern row) is TMS row 3.
    conn.execute("INSERT INTO tiles VALUES (2, 1, 3, ?)", (PNG,))
    conn.executemany("INSERT INTO metadata VALUES (?, ?)", [("bounds", "-10,-5,10,5"), ("attribution", "© them")])
    conn.commit()
    conn.close()
    store = open_tile_store(path)
    assert isinstance(store, MBTiles) and store.exists()
    assert store.get(2, 1, 0) == (PNG, "png")
    assert store.get(2, 1, 3) is None
    meta = store.metadata()
    assert (meta["minzoom"], meta["maxzoom"], meta["bounds"], meta["attribution"]) == (2, 2, [-10, -5, 10, 5], "© them")
    store.close()


def test_mbtiles_we_write_are_tms_on_disk(tmp_path):
    path = tmp_path / "ours.mbtiles"
    store = MBTiles(path, writable=True)
    store.begin()
    store.put(3, 5, 1, PNG, "png")
    store.commit()
    store.update_metadata(bounds=[1, 2, 3, 4], minzoom=3, maxzoom=3, attribution="a", source="s", fmt="png")
    store.close()
    conn = sqlite3.connect(path)
    assert conn.execute("SELECT zoom_level, tile_column, tile_row FROM tiles").fetchall() == [(3, 5, 6)]
    assert dict(conn.execute("SELECT name, value FROM metadata"))["format"] == "png"
    conn.close()
    assert MBTiles(path).get(3, 5, 1) == (PNG, "png")


def test_a_file_that_is_not_mbtiles_is_simply_no_basemap(tmp_path):
    path = tmp_path / "broken.mbtiles"
    path.write_bytes(b"not sqlite at all" * 100)
    assert not MBTiles(path).exists()
    assert not MBTiles(tmp_path / "absent.mbtiles").exists()


def test_fetch_refuses_an_area_that_is_too_large_before_downloading_anything(tmp_path):
    store = FolderTiles(tmp_path / "t")
    with pytest.raises(TooManyTiles) as err:
        fetch_tiles(store, "http://127.0.0.1:9/{z}/{x}/{y}.png", (-10, -10, 10, 10), 0, 12, max_tiles=1000)
    assert "limit is 1,000" in str(err.value) and "--bbox" in str(err.value)
    assert not (tmp_path / "t").exists()


def test_command_line_arguments_are_checked():
    assert parse_bbox("-82.47,27.36,-82.43,27.39") == (-82.47, 27.36, -82.43, 27.39)
    assert parse_zoom("12-17") == (12, 17) and parse_zoom("14") == (14, 14)
    for bad in ["1,2,3", "a,b,c,d", "10,0,5,1", "0,10,1,5", "0,0,nan,1", "-190,0,0,1"]:
        with pytest.raises(click.BadParameter):
            parse_bbox(bad)
    for bad in ["17-12", "x", "-1", "0-30"]:
        with pytest.raises(click.BadParameter):
            parse_zoom(bad)
    for bad in ["ftp://h/{z}/{x}/{y}", "http://h/{z}/{x}.png"]:
        with pytest.raises(click.BadParameter):
            check_url_template(bad)
