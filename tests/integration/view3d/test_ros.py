"""The 3D view with real ROS publishers in another process: a description over /robot_description
(transient local: published before the server starts) and a bad one answered with its line; a point
cloud thinned to the bound with its extent kept and sent as one binary frame; bad clouds counted,
never raised; the cloud's long poll holding a stream slot."""

import struct
import threading

import numpy as np
import pytest
import requests

from rover_web.view3d.cloud import decode
from tests.support.view3d_support import BAD_URDF, BAD_URDF_LINE, ROBOT_URDF
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

STRING = "std_msgs/msg/String"
CLOUD = "sensor_msgs/msg/PointCloud2"


def robot(server):
    return requests.get(server.url + "/api/3d/robot", timeout=5).json()


def test_the_description_from_the_topic_and_a_bad_one_with_its_line(live_server_factory, ros_peer):
    peer = ros_peer("description_peer")
    peer.advertise("/robot_description", STRING, qos="latched")
    peer.publish("/robot_description", {"data": ROBOT_URDF})  # before the server exists: transient local
    server = live_server_factory()
    got = wait_until(lambda: (r := robot(server))["state"] == "ok" and r, 15, "the latched description")
    assert got["source"] == "/robot_description" and got["links"] == ["base_link", "arm", "mast"]
    peer.publish("/robot_description", {"data": BAD_URDF})
    bad = wait_until(lambda: (r := robot(server))["state"] == "error" and r, 15, "the bad description")
    assert bad["error"]["line"] == BAD_URDF_LINE and bad["seq"] > got["seq"]


def cloud(points, fields=("x", "y", "z", "intensity")):
    data = b"".join(struct.pack("<4f", *p) for p in points)
    return {"header": {"frame_id": "lidar"}, "height": 1, "width": len(points),
            "fields": [{"name": n, "offset": 4 * k, "datatype": 7, "count": 1} for k, n in enumerate(fields)],
            "is_bigendian": False, "point_step": 16, "row_step": 16 * len(points), "data": list(data),
            "is_dense": True}


def test_a_cloud_is_thinned_to_the_bound_with_its_extent_kept(live_server_factory, ros_peer):
    rng = np.random.default_rng(3)
    pts = np.concatenate([rng.uniform(-5, 5, (6000, 3)), rng.uniform(0, 100, (6000, 1))], axis=1)
    pts[0, :3] = (-20.0, 0.0, 0.0)   # far outliers: the extent must keep them
    pts[1, :3] = (0.0, 30.0, 4.0)
    server = live_server_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points", ROVER_WEB_POINTCLOUD_MAX_POINTS=1000)
    peer = ros_peer("cloud_peer")
    peer.advertise("/points", CLOUD, qos="sensor_data")
    peer.wait_match("/points")
    msg = cloud(pts.tolist())
    bad = cloud([(0, 0, 0, 0)], fields=("a", "b", "c", "d"))

    def frame():
        peer.publish("/points", bad)
        peer.publish("/points", msg)
        reply = requests.get(server.url + "/api/3d/cloud", params={"after": 0, "wait": 1}, timeout=5)
        return reply.status_code == 200 and reply
    reply = wait_until(frame, 20, "a thinned cloud", interval=0.3)
    assert reply.headers["Content-Type"] == "application/octet-stream"
    header, xyz, intensity = decode(reply.content)
    assert 0 < header["count"] <= 1000 and header["source_points"] == 6000
    assert header["frame_id"] == "lidar" and len(intensity) == header["count"]
    voxel = header["voxel_m"]
    assert xyz.min(axis=0)[0] >= -20.0 - 1e-6 and xyz.min(axis=0)[0] <= -20.0 + voxel
    assert xyz.max(axis=0)[1] >= 30.0 - voxel
    assert set(map(tuple, xyz.round(4).tolist())) <= set(map(tuple, pts[:, :3].astype(np.float32).round(4).tolist()))
    seq = int(reply.headers["X-Cloud-Seq"])
    # nothing newer: 204 after the wait, with the sequence the page has
    again = requests.get(server.url + "/api/3d/cloud", params={"after": seq, "wait": 0.3}, timeout=5)
    assert again.status_code in (200, 204)

    def bad_counted():
        peer.publish("/points", bad)  # best effort, as a lidar's: a loaded machine may lose one
        return robot(server)["cloud"]["skipped"].get("no_xyz")
    assert wait_until(bad_counted, 30, "the bad cloud counted", interval=0.3)


def test_a_waiting_cloud_request_holds_a_stream_slot(live_server_factory):
    server = live_server_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points", ROVER_WEB_MAX_STREAMS=3,
                                 ROVER_WEB_STREAMS_RESERVED=1, ROVER_WEB_MAX_STREAMS_PER_CLIENT=3)
    replies = []
    waiting = [threading.Thread(target=lambda: replies.append(requests.get(
        server.url + "/api/3d/cloud", params={"wait": 2}, timeout=10).status_code)) for _ in range(2)]
    for t in waiting:
        t.start()
    wait_until(lambda: server.rover.streams.count >= 2, 5, "two requests waiting")
    refused = requests.get(server.url + "/api/3d/cloud", params={"wait": 2}, timeout=10)
    for t in waiting:
        t.join()
    assert refused.status_code == 503 and refused.json()["error"] == "too_many_streams"
    assert replies == [204, 204]
    assert requests.get(server.url + "/api/3d/cloud", params={"wait": 0}, timeout=5).status_code == 204
