"""The simulated rover's URDF: parsed by the 3D view's parser, and its sensor links where the
simulator's /tf_static puts them (the same Mount numbers), so the model and TF agree."""

import math

import pytest
from lxml import etree

from rover_web.sim.frames import MOUNTS
from rover_web.sim.model import rover_urdf
from rover_web.view3d.urdf_model import parse


def test_the_model_parses_with_one_root_and_every_mount():
    model = parse(rover_urdf())
    assert model.root == "base_link"
    assert {m.frame for m in MOUNTS} <= set(model.links)
    assert all(j["type"] == "fixed" and j["parent"] == "base_link" for j in model.joints)


@pytest.mark.parametrize("mount", MOUNTS, ids=lambda m: m.frame)
def test_each_sensor_joint_is_its_tf_static_mount(mount):
    root = etree.fromstring(rover_urdf().encode())
    origin = next(
        j.find("origin") for j in root.findall("joint") if j.find("child").get("link") == mount.frame)
    xyz = [float(v) for v in origin.get("xyz").split()]
    rpy = [float(v) for v in origin.get("rpy").split()]
    assert xyz == pytest.approx([mount.x, mount.y, mount.z], abs=1e-6)
    assert rpy == pytest.approx([mount.roll, mount.pitch, mount.yaw], abs=1e-5)
    assert not any(math.isnan(v) for v in xyz + rpy)
