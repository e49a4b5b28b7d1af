"""A basemap out of the box: the demo's drawn GeoJSON basemap (map_files/basemap/) rendered by the
GPS map in Chromium, read back from the pixels, with its attribution shown; then an imported one."""

import io
import json

import numpy as np
import pytest
from PIL import Image

from tests.browser.test_waypoints_map import open_map

pytestmark = pytest.mark.browser

WATER = (0x1d, 0x4f, 0x7a)
LAND_OR_PARK = [(0x2b, 0x3a, 0x2e), (0x2f, 0x4a, 0x33)]
BACKGROUND = (0x17, 0x21, 0x2b)
LAKE_CENTRE = (-82.45035, 27.37445)


def colour_at(page, lng, lat):
    """The rendered colour at (lng, lat): the median of a 5x5 patch, so a grid line does not decide."""
    x, y = page.evaluate("([lng, lat]) => { const p = window.roverWaypointsMap.project([lng, lat]);"
                         " return [p.x, p.y]; }", [lng, lat])
    shot = np.asarray(Image.open(io.BytesIO(page.locator("#wp-map").screenshot())).convert("RGB")).astype(int)
    patch = shot[int(y) - 2:int(y) + 3, int(x) - 2:int(x) + 3].reshape(-1, 3)
    return tuple(int(v) for v in np.median(patch, axis=0))


def close(a, b, tolerance=6):
    return all(abs(p - q) <= tolerance for p, q in zip(a, b, strict=True))


def settle(page, zoom, centre=LAKE_CENTRE):
    page.evaluate("([c, z]) => window.roverWaypointsMap.jumpTo({center: c, zoom: z})", [list(centre), zoom])
    page.wait_for_function("() => window.roverWaypointsMap.loaded() && window.roverWaypointsMap.areTilesLoaded()",
                           timeout=15000)
    page.wait_for_timeout(300)


def test_the_demo_shows_its_lake_and_land_with_the_attribution(live_server, page):
    open_map(page, live_server.url)
    assert page.locator("#wp-map-note").is_hidden()  # a basemap is installed: no "no basemap" note
    settle(page, 13)
    assert close(colour_at(page, *LAKE_CENTRE), WATER)
    assert close(colour_at(page, -82.45035, 27.3815), LAND_OR_PARK[1])  # the park, 100 m north of the shore
    assert close(colour_at(page, -82.470, 27.360), LAND_OR_PARK[0])              # land, far from the lake
    assert not close(colour_at(page, -82.470, 27.360), BACKGROUND)
    attribution = page.locator(".maplibregl-ctrl-attrib-inner").text_content()
    assert "schematic" in attribution
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_an_imported_geojson_is_drawn(live_server_factory, page, tmp_path):
    folder = tmp_path / "drawn"
    folder.mkdir()
    square = [[-82.452, 27.372], [-82.448, 27.372], [-82.448, 27.376], [-82.452, 27.376], [-82.452, 27.372]]
    (folder / "pond.geojson").write_text(json.dumps({
        "type": "FeatureCollection", "attribution": "© the pond survey", "features": [
            {"type": "Feature", "properties": {"kind": "sand"}, "geometry": {"type": "Polygon",
                                                                           "coordinates": [square]}}]}))
    server = live_server_factory(ROVER_WEB_MAP_GEOJSON_DIR=str(folder))
    open_map(page, server.url)
    settle(page, 15, centre=(-82.45, 27.374))
    # Sand inside the square (the geofence layer above it may darken it a little).
    assert close(colour_at(page, -82.45, 27.374), (0x5a, 0x52, 0x38), tolerance=14)
    assert close(colour_at(page, -82.455, 27.374), BACKGROUND)            # nothing drawn outside it
    assert "© the pond survey" in page.locator(".maplibregl-ctrl-attrib-inner").text_content()
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_the_fleet_page_draws_the_same_demo_basemap_and_does_not_say_none_is_installed(live_server, page):
    # The fleet page's note looked at raster tiles only, so with the demo's drawn basemap (and no
    # tiles) it said "No basemap installed" over a map that drew it.
    page.goto(live_server.url + "/robots")
    page.wait_for_selector("#fleet-map[data-ready='yes']", timeout=20000)
    assert page.locator("#fleet-map-note").is_hidden()
    page.wait_for_function("() => document.querySelector('#fleet-map .maplibregl-ctrl-attrib-inner')"
                           " && document.querySelector('#fleet-map .maplibregl-ctrl-attrib-inner').textContent"
                           ".includes('schematic')", timeout=15000)
