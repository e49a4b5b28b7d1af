"""LiveMap keep-out areas: which `keep_out` entries load, and which goals they refuse."""

import json
import shutil

import pytest

from rover_web.config import ROOT, ConfigError
from rover_web.geofence import OutsideGeofence
from rover_web.livemap.keep_out import check_goal, parse_keep_out
from rover_web.livemap.map_files import load_catalog

ROOM = [{"name": "electrical room", "polygon": [[34, 0], [37.5, 0], [37.5, 4], [34, 4]]}]


def test_the_shipped_basement_has_a_keep_out_area():
    basement = load_catalog(ROOT / "map_files" / "all_maps.json")["Science Hall Basement"]
    assert [a.as_dict() for a in basement.keep_out] == [
        {"name": "electrical room", "polygon": [[34.0, 0.0], [37.5, 0.0], [37.5, 4.0], [34.0, 4.0]]}]
    for w in basement.waypoints:  # no named waypoint is a goal the server would refuse
        check_goal(basement.keep_out, basement.name, w.x, w.y)


@pytest.mark.parametrize("x, y, refused", [
    (35, 2, True), (34, 2, True), (37.5, 4, True),   # inside, on an edge, on a corner
    (33.99, 2, False), (36, 4.01, False), (0, 0, False),
])
def test_goals_inside_or_on_the_edge_are_refused(x, y, refused):
    areas = parse_keep_out(ROOM, "keep_out")
    if refused:
        with pytest.raises(OutsideGeofence) as exc:
            check_goal(areas, "Basement", x, y)
        assert exc.value.details["reason"] == "inside_keep_out" and "'electrical room'" in str(exc.value)
    else:
        check_goal(areas, "Basement", x, y)


@pytest.mark.parametrize("raw, words", [
    ({"polygon": []}, "expected a list"),
    ([{"polygon": [[0, 0], [1, 1]]}], "3 to"),
    ([{"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]]}], "Self-intersection"),
    ([{"polygon": [[0, 0], [1, 0], [2, 0]]}], "not a simple polygon"),
    ([{"polygon": [[0, 0], [1, "0"], [1, 1]]}], "polygon[1]"),
    ([{"polygon": [[0, 0], [1, 0], [1, 1]], "colour": "red"}], "expected"),
])
def test_bad_areas_are_refused_naming_the_key(raw, words):
    with pytest.raises(ValueError, match="keep_out") as exc:
        parse_keep_out(raw, "keep_out")
    assert words in str(exc.value)


def test_a_bad_keep_out_stops_the_catalog_from_loading(tmp_path):
    shutil.copytree(ROOT / "map_files" / "basement", tmp_path / "basement")
    catalog = json.loads((ROOT / "map_files" / "all_maps.json").read_text())
    entry = catalog["Science Hall Basement"]
    entry["keep_out"] = [{"name": "bow", "polygon": [[0, 0], [1, 1], [1, 0], [0, 1]]}]
    (tmp_path / "all_maps.json").write_text(json.dumps({"Science Hall Basement": entry}))
    with pytest.raises(ConfigError, match=r'"Science Hall Basement".keep_out\[0\].polygon.*Self-intersection'):
        load_catalog(tmp_path / "all_maps.json")
