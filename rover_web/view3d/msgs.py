"""The 3D view's messages read into plain values: std_msgs/String (the robot description),
sensor_msgs/PointCloud2 and visualization_msgs/MarkerArray (in 3D: the overlays keep only x, y, yaw)."""

from __future__ import annotations

from rover_web.overlays.bounds import FRAME_ID_MAX, MARKERS_MAX_COUNT, NS_MAX, TEXT_MAX
from rover_web.ros.convert import stamp_to_float
from rover_web.ros.graph import deserializer  # noqa: F401  (the feature's subscriptions take it from here)

from . import cloud

STRING = "std_msgs/msg/String"
POINT_CLOUD2 = "sensor_msgs/msg/PointCloud2"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"


def description(msg) -> str:
    return msg.data


def point_cloud(msg) -> cloud.Cloud:
    fields = [(f.name, int(f.offset), int(f.datatype), int(f.count)) for f in msg.fields]
    return cloud.read(msg.header.frame_id.lstrip("/"), stamp_to_float(msg.header.stamp), int(msg.height),
                      int(msg.width), fields, int(msg.point_step), int(msg.row_step), bool(msg.is_bigendian),
                      bytes(msg.data))


def markers(msg, most: int = MARKERS_MAX_COUNT) -> list[dict]:
    """The first `most` markers as plain values (the rest never converted), names and text truncated
    as the overlays truncate them."""
    out = []
    for m in msg.markers[:most]:
        p, q, c = m.pose.position, m.pose.orientation, m.color
        out.append({"ns": m.ns[:NS_MAX], "id": int(m.id), "type": int(m.type), "action": int(m.action),
                    "frame_id": m.header.frame_id[:FRAME_ID_MAX].lstrip("/"), "stamp": stamp_to_float(m.header.stamp),
                    "pose": [p.x, p.y, p.z, q.x, q.y, q.z, q.w], "scale": [m.scale.x, m.scale.y, m.scale.z],
                    "color": [c.r, c.g, c.b, c.a],
                    "points": [[pt.x, pt.y, pt.z] for pt in m.points],
                    "colors": [[k.r, k.g, k.b, k.a] for k in m.colors],
                    "text": m.text[:TEXT_MAX], "mesh_resource": m.mesh_resource[:FRAME_ID_MAX * 4],
                    "lifetime_s": m.lifetime.sec + m.lifetime.nanosec * 1e-9,
                    "frame_locked": bool(m.frame_locked)})
    return out
