"""Loading floorplans: the shipped catalog, map_server yaml, and every way a file can be wrong."""

import io
import json
import math
import os
from pathlib import Path

import pytest
from PIL import Image

from rover_web.config import ROOT, ConfigError
from rover_web.livemap.map_files import first_waypoint_or_centre, load_catalog, maps_file_path

SHIPPED = ROOT / "map_files" / "all_maps.json"


def test_the_shipped_floorplans_load_with_their_waypoints_on_free_floor():
    catalog = load_catalog(SHIPPED)
    assert list(catalog) == ["Science Hall Basement", "Robotics Lab"]
    basement, lab = catalog.values()
    assert (basement.geometry.width_px, basement.geometry.height_px) == (800, 480)
    assert basement.files["png"] == {"file_name": "basement.png", "cm_per_pixel": 5.0,
                                     "pixel_width": 800, "pixel_height": 480}
    assert lab.image_path.suffix == ".pgm" and lab.files["yaml_file"] == "lab.yaml"
    assert (lab.geometry.origin_x, lab.geometry.origin_y) == (-6.0, -4.5)
    for definition in catalog.values():
        assert len(definition.waypoints) >= 4
        assert max(definition.geometry.width_px, definition.geometry.height_px) <= 1500
        with Image.open(io.BytesIO(definition.png())) as image:
            assert image.format == "PNG"
            assert image.size == (definition.geometry.width_px, definition.geometry.height_px)
            grey = image.convert("L")
            for w in definition.waypoints:  # a robot sent to a waypoint must not be sent into a wall
                col, row = definition.geometry.cell_of(w.x, w.y)
                assert grey.getpixel((col, row)) == 254, f"{definition.name}: {w.name} is not on free floor"
        with Image.open(io.BytesIO(definition.thumbnail())) as thumb:
            assert max(thumb.size) == 320
    assert first_waypoint_or_centre(basement) == (2.0, 10.5, 0.0)


def test_the_shipped_basement_also_loads_as_a_plain_map_server_yaml():
    catalog = load_catalog(ROOT / "map_files" / "basement" / "basement.yaml")
    (definition,) = catalog.values()
    assert definition.name == "basement"
    assert definition.geometry == load_catalog(SHIPPED)["Science Hall Basement"].geometry


def test_maps_file_setting_paths():
    assert maps_file_path(None) is None and maps_file_path("") is None
    assert maps_file_path("map_files/all_maps.json") == ROOT / "map_files" / "all_maps.json"
    assert maps_file_path("/srv/maps/x.yaml") == Path("/srv/maps/x.yaml")


# --- building catalogs in a temporary folder ---


def write_image(path: Path, size=(40, 20), value=254, mode="L"):
    path.parent.mkdir(parents=True, exist_ok=True)
    image = Image.new(mode, size, value)
    image.save(path)
    return path


def write_catalog(folder: Path, entries: dict) -> Path:
    path = folder / "all_maps.json"
    path.write_text(json.dumps(entries))
    return path


def campus_entry(**files):
    entry = {"files": {"path": "m/", "png_file": {"file_name": "m.png", "cm_per_pixel": 10},
                       "waypoint_file": "w.json"},
             "yaml_parameters": {"resolution": 0.1, "origin": [1.0, 2.0, 0.0]}}
    entry["files"].update(files)
    return entry


@pytest.fixture
def folder(tmp_path):
    write_image(tmp_path / "m" / "m.png")
    (tmp_path / "m" / "w.json").write_text(json.dumps({"waypoints": [{"name": "A", "x": 2.0, "y": 3.0}]}))
    return tmp_path


def test_campus_format_with_waypoints_in_every_accepted_shape(folder):
    definition = load_catalog(write_catalog(folder, {"Hall": campus_entry()}))["Hall"]
    g = definition.geometry
    assert (g.width_px, g.height_px, g.resolution_m, g.origin_x, g.origin_y) == (40, 20, 0.1, 1.0, 2.0)
    assert [(w.name, w.x, w.y, w.yaw) for w in definition.waypoints] == [("A", 2.0, 3.0, 0.0)]
    for shape in ([{"name": "A", "x": 2.0, "y": 3.0, "yaw": 1.0}], {"A": {"x": 2.0, "y": 3.0, "yaw": 1.0}}):
        (folder / "m" / "w.json").write_text(json.dumps(shape))
        (w,) = load_catalog(write_catalog(folder, {"Hall": campus_entry()}))["Hall"].waypoints
        assert (w.name, w.x, w.y, w.yaw) == ("A", 2.0, 3.0, 1.0)


def test_map_server_yaml_with_a_negated_pgm_is_shown_with_free_space_light(tmp_path):
    image = Image.new("L", (30, 10), 0)          # negate: 1 means dark pixels are free...
    image.putpixel((0, 0), 255)                  # ...and this one is occupied
    image.save(tmp_path / "neg.pgm")
    (tmp_path / "neg.yaml").write_text("image: neg.pgm\nresolution: 0.5\norigin: [0, 0, 0]\nnegate: 1\n"
                                       "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n")
    definition = load_catalog(tmp_path / "neg.yaml")["neg"]
    assert definition.yaml["negate"] == 1 and definition.yaml["free_thresh"] == 0.196
    with Image.open(io.BytesIO(definition.png())) as shown:
        assert shown.format == "PNG" and shown.size == (30, 10)
        assert shown.convert("L").getpixel((5, 5)) == 255 and shown.convert("L").getpixel((0, 0)) == 0


def expect_error(path: Path, *words):
    with pytest.raises(ConfigError) as err:
        load_catalog(path)
    message = str(err.value)
    for word in words:
        assert word in message, message
    return message


def test_missing_or_malformed_catalog(tmp_path):
    expect_error(tmp_path / "nope.json", "nope.json", "not found")
    bad = tmp_path / "all_maps.json"
    bad.write_text("{not json")
    expect_error(bad, "all_maps.json", "not valid JSON")
    bad.write_text("[]")
    expect_error(bad, "all_maps.json", "expected an object")


@pytest.mark.parametrize("change, words", [
    (lambda e: e["files"].pop("png_file"), ['"Hall".files.png_file', "missing"]),
    (lambda e: e.pop("yaml_parameters"), ['"Hall".yaml_parameters', "missing"]),
    (lambda e: e["yaml_parameters"].pop("origin"), ['"Hall".yaml_parameters.origin', "missing"]),
    (lambda e: e["yaml_parameters"].update(resolution=-1), ['"Hall".yaml_parameters.resolution', "positive"]),
    (lambda e: e["yaml_parameters"].update(resolution="fine"), ["yaml_parameters.resolution", "number"]),
    (lambda e: e["yaml_parameters"].update(origin=[1, 2, 3, 4]), ["yaml_parameters.origin", "[x, y, yaw]"]),
    (lambda e: e["yaml_parameters"].update(negate=2), ["yaml_parameters.negate", "0 or 1"]),
    (lambda e: e["yaml_parameters"].update(mode="fancy"), ["yaml_parameters.mode", "trinary"]),
    (lambda e: e["yaml_parameters"].update(free_thresh=0.9), ["yaml_parameters.free_thresh"]),
    (lambda e: e["files"]["png_file"].update(cm_per_pixel=5), ["png_file.cm_per_pixel", "disagrees"]),
    (lambda e: e["files"]["png_file"].update(file_name="gone.png"), ["png_file.file_name", "not found"]),
    (lambda e: e["files"]["png_file"].update(file_name="w.json"), ["png_file.file_name", ".png or .pgm"]),
    (lambda e: e["files"].update(waypoint_file="gone.json"), ["gone.json", "not found"]),
    (lambda e: e["files"].update(colour="red"), ['"Hall".files.colour', "unknown key"]),
    (lambda e: e["files"].update(yaml_file="m.yaml"), ["files.yaml_file", "not both"]),
])
def test_every_problem_names_the_file_and_the_key(folder, change, words):
    entry = campus_entry()
    change(entry)
    expect_error(write_catalog(folder, {"Hall": entry}), "all_maps.json", *words)


def test_a_corrupt_image_fails_at_start(folder):
    (folder / "m" / "m.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"garbage" * 10)
    expect_error(write_catalog(folder, {"Hall": campus_entry()}), "png_file.file_name", "not a readable image")


@pytest.mark.parametrize("fmt", ["BMP", "GIF", "TIFF"])
def test_a_floorplan_is_read_only_as_png_or_pgm_whatever_its_name(folder, fmt):
    Image.new("L", (40, 20), 254).save(folder / "m" / "m.png", fmt)  # another format under a .png name
    expect_error(write_catalog(folder, {"Hall": campus_entry()}), "png_file.file_name", "not a readable image")


@pytest.mark.parametrize("waypoints, words", [
    ([{"name": "Far", "x": 100.0, "y": 3.0}], ["w.json", "waypoints[0]", "outside the map"]),
    ([{"name": "A", "x": 2.0, "y": 3.0}, {"name": "A", "x": 3.0, "y": 3.0}], ["waypoints[1].name", "duplicate"]),
    ([{"name": "A", "x": "2", "y": 3.0}], ["waypoints[0].x", "number"]),
    ([{"name": "A", "y": 3.0}], ["waypoints[0].x", "missing"]),
    ([{"name": "A", "x": 2.0, "y": 3.0, "z": 1}], ["waypoints[0].z", "unknown key"]),
    ([{"name": "a/b", "x": 2.0, "y": 3.0}], ["'a/b'", "may not contain"]),
])
def test_bad_waypoints_name_the_waypoint_file_and_entry(folder, waypoints, words):
    (folder / "m" / "w.json").write_text(json.dumps({"waypoints": waypoints}))
    expect_error(write_catalog(folder, {"Hall": campus_entry()}), *words)


@pytest.mark.parametrize("files", [
    {"path": "../"},
    {"path": "/etc/"},
    {"png_file": {"file_name": "../../secret.png", "cm_per_pixel": 10}},
    {"png_file": {"file_name": "/etc/passwd.png", "cm_per_pixel": 10}},
    {"waypoint_file": "../w.json"},
    {"waypoint_file": "sub/../../w.json"},
])
def test_path_traversal_in_file_names_is_refused_at_load(folder, files):
    write_image(folder.parent / "secret.png")
    (folder.parent / "w.json").write_text("[]")
    message = expect_error(write_catalog(folder, {"Hall": campus_entry(**files)}), "all_maps.json")
    assert "'..'" in message or "outside" in message


def test_a_symlink_leading_out_of_the_maps_folder_is_refused(folder, tmp_path_factory):
    elsewhere = write_image(tmp_path_factory.mktemp("elsewhere") / "plan.png")
    os.symlink(elsewhere, folder / "m" / "link.png")
    entry = campus_entry(png_file={"file_name": "link.png", "cm_per_pixel": 10})
    expect_error(write_catalog(folder, {"Hall": entry}), "png_file.file_name", "leads outside")


def test_a_map_server_yaml_may_not_reach_outside_either(tmp_path):
    write_image(tmp_path / "outside.png")
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "x.yaml").write_text("image: ../outside.png\nresolution: 0.1\norigin: [0, 0, 0]\n")
    expect_error(tmp_path / "maps" / "x.yaml", "x.yaml", "image", "'..'")
    outside = tmp_path / "outside.png"
    (tmp_path / "maps" / "x.yaml").write_text(f"image: {outside}\nresolution: 0.1\norigin: [0, 0, 0]\n")
    expect_error(tmp_path / "maps" / "x.yaml", "image", "leads outside")
    (tmp_path / "maps" / "x.yaml").write_text("image: [1\n")
    expect_error(tmp_path / "maps" / "x.yaml", "not valid YAML")
    (tmp_path / "maps" / "x.yaml").write_text("resolution: 0.1\norigin: [0, 0, 0]\n")
    expect_error(tmp_path / "maps" / "x.yaml", "x.yaml: image: missing")


@pytest.mark.parametrize("name", ["a/b", "..", "tab\there", "x" * 81, ""])
def test_map_names_that_cannot_be_a_url_segment_are_refused(folder, name):
    expect_error(write_catalog(folder, {name: campus_entry()}), "all_maps.json", "names")


def test_origin_yaw_from_the_yaml_is_kept(folder):
    entry = campus_entry()
    entry["yaml_parameters"]["origin"] = [1.0, 2.0, math.pi / 2]
    (folder / "m" / "w.json").write_text("[]")
    g = load_catalog(write_catalog(folder, {"Hall": entry}))["Hall"].geometry
    assert g.origin_yaw == pytest.approx(math.pi / 2)
