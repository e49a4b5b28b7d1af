"""package:// meshes: found through the ament index, and never from outside the package's share folder."""

import os

import pytest

from rover_web.view3d.meshes import MeshRefused, package_uri, resolve
from tests.support.view3d_support import ament_prefix, stl_box


@pytest.fixture
def prefix(tmp_path, monkeypatch):
    found = ament_prefix(tmp_path)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(found))
    return found


def test_a_mesh_inside_the_share(prefix):
    found = resolve("testbot_description", "meshes/mast.stl")
    assert found.path == os.path.realpath(prefix / "share" / "testbot_description" / "meshes" / "mast.stl")
    assert found.size == len(stl_box()) and found.content_type == "model/stl"


@pytest.mark.parametrize("package, path, code", [
    ("testbot_description", "../../../secret.stl", "outside_package"),
    ("testbot_description", "meshes/../../testbot_description/meshes/mast.stl", "outside_package"),
    ("testbot_description", "meshes/./mast.stl", "outside_package"),
    ("testbot_description", "meshes/escape.stl", "outside_package"),
    ("testbot_description", "/etc/passwd.stl", "bad_mesh_path"),
    ("testbot_description", "meshes\\mast.stl", "bad_mesh_path"),
    ("testbot_description", "", "bad_mesh_path"),
    ("testbot_description", "a" * 1100 + ".stl", "bad_mesh_path"),
    ("testbot_description", "meshes/mast.py", "not_a_mesh"),
    ("no_such_package", "meshes/mast.stl", "unknown_package"),
    ("../etc", "passwd.stl", "bad_package"),
])
def test_refused(prefix, package, path, code):
    with pytest.raises(MeshRefused) as caught:
        resolve(package, path)
    assert caught.value.code == code


def test_a_symlinked_share_folder_is_followed_but_not_left(tmp_path, monkeypatch):
    prefix = ament_prefix(tmp_path)
    real_share = tmp_path / "elsewhere"
    (prefix / "share" / "testbot_description").rename(real_share)
    (prefix / "share" / "testbot_description").symlink_to(real_share)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    assert resolve("testbot_description", "meshes/mast.stl").size == len(stl_box())
    with pytest.raises(MeshRefused):
        resolve("testbot_description", "meshes/escape.stl")


def test_package_uri():
    assert package_uri("package://pkg/meshes/a.stl") == ("pkg", "meshes/a.stl")
    assert package_uri("file:///a.stl") is None
