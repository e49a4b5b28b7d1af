"""The 3D view's service: poses looked up only while someone watches, one thinning per cloud whatever
the number of viewers, a new description replacing the last."""

import threading
import types

import numpy as np
import pytest

from rover_web import config
from rover_web.events.hub import EventHub
from rover_web.tf.buffer import TfBuffer
from rover_web.view3d import cloud
from rover_web.view3d.service import CHANNELS, View3dService
from tests.support.view3d_support import BAD_URDF, ROBOT_URDF


@pytest.fixture
def service():
    settings = config.defaults()
    settings["ROVER_WEB_POINTCLOUD_TOPIC"] = "/points"
    hub = EventHub()
    hub.register(*CHANNELS)
    rover = types.SimpleNamespace(config=settings, hub=hub, stopping=threading.Event())
    s = View3dService(rover)
    s.tf = TfBuffer()
    s.tf.set_transform("odom", "base_link", (1, 2, 0), (0, 0, 0, 1), 0, static=True)
    yield s
    hub.close()


def test_poses_only_while_an_event_stream_is_open(service):
    service.tick()
    assert service.hub.latest("view3d") is None
    with service.hub.subscribe(["view3d"]):
        service.tick()
    poses = service.hub.latest("view3d")
    assert poses["base"] == "base_link"
    assert poses["frames"]["odom"] == [-1.0, -2.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def test_one_thinning_per_cloud_for_every_viewer(service, monkeypatch):
    calls = []
    real = cloud.voxel_thin
    monkeypatch.setattr(cloud, "voxel_thin", lambda *a, **k: calls.append(1) or real(*a, **k))
    xyz = np.random.default_rng(1).uniform(-1, 1, (50_000, 3)).astype(np.float32)
    service.on_cloud(lambda: cloud.Cloud("lidar", 1.0, xyz, None, len(xyz)))
    frames = [service.cloud_after(0, 1.0) for _ in range(5)]
    assert len(calls) == 1
    assert all(f == frames[0] for f in frames) and frames[0][0] == 1
    header, thinned, _ = cloud.decode(frames[0][1])
    assert header["count"] == len(thinned) <= 20_000
    assert service.cloud_after(1, 0.05) == (1, None)  # nothing newer


def test_a_waiting_viewer_wakes_for_a_new_cloud(service):
    xyz = np.zeros((3, 3), np.float32)
    got = []
    waiter = threading.Thread(target=lambda: got.append(service.cloud_after(0, 5.0)))
    waiter.start()
    service.on_cloud(lambda: cloud.Cloud("lidar", 1.0, xyz, None, 3))
    waiter.join(5)
    assert got and got[0][0] == 1 and got[0][1] is not None


def test_a_bad_cloud_is_counted_not_raised(service):
    def bad():
        raise cloud.BadCloud("no_xyz: the cloud has no x, y and z fields")
    service.on_cloud(bad)
    assert service.cloud_counts()["skipped"] == {"no_xyz": 1}


def test_a_new_description_replaces_the_last(service):
    service.on_description(ROBOT_URDF, "/robot_description")
    assert service.robot()["state"] == "ok"
    service.on_description(BAD_URDF, "/robot_description")
    robot = service.robot()
    assert robot["state"] == "error" and robot["seq"] == 2 and "urdf" not in robot


def test_a_cloud_is_placed_where_its_frame_was_at_its_stamp(service):
    service.tf.set_transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    service.tf.set_transform("odom", "moving", (0, 0, 0), (0, 0, 0, 1), 10 * 10**9, static=False)
    service.tf.set_transform("odom", "moving", (2, 0, 0), (0, 0, 0, 1), 11 * 10**9, static=False)
    xyz = np.zeros((3, 3), np.float32)
    service.on_cloud(lambda: cloud.Cloud("moving", 10.25, xyz, None, 3))
    header, _, _ = cloud.decode(service.cloud_after(0, 1.0)[1])
    assert header["at_stamp"]["odom"][:3] == pytest.approx([0.5, 0, 0])   # a quarter of the way, not the newest
    assert header["at_stamp"]["map"][:3] == pytest.approx([0.5, 0, 0])
    service.on_cloud(lambda: cloud.Cloud("moving", 99.0, xyz, None, 3))  # past the newest transform
    header, _, _ = cloud.decode(service.cloud_after(1, 1.0)[1])
    assert "odom" not in header.get("at_stamp", {})


def test_a_cloud_over_its_bound_or_unwatched_is_never_deserialized(service):
    from rover_web.overlays.bounds import bounded

    deserialized = []
    on_raw = bounded(service.cloud_bound, 100, lambda raw: deserialized.append(raw) or raw, lambda m: None,
                     service.cloud_watched)
    on_raw(b"x" * 50)                      # nobody asked for a cloud yet
    assert deserialized == [] and service.cloud_counts()["skipped"] == {}
    service.cloud_after(0, 0)              # a viewer asks
    on_raw(b"x" * 500)                     # over the bound: counted, dropped as bytes
    assert deserialized == [] and service.cloud_counts()["skipped"] == {"too_large": 1}
    on_raw(b"x" * 50)
    assert deserialized == [b"x" * 50]
