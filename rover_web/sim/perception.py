"""The simulated rover's perception topics, so the demo's LiveMap shows every overlay.

On the rover's node: `scan` (sensor_msgs/LaserScan ray-cast from the floorplan from the laser's
mount, frame `base_scan`, upside down, turned and off centre (frames.py), stamped like the odometry
whose pose it was cast from), `global_costmap/costmap` (the whole floorplan inflated, in `map`,
transient local, every 10 s), `local_costmap/costmap` (a 6 m window around the robot in `odom`, as
Nav2's rolling window is, 1 Hz), `global_costmap/published_footprint` (its square footprint in
`base_link`, 5 Hz) and
`visualization_marker_array` (its map's waypoints as spheres and labels, the route through them
as a line, and a heading arrow in `base_link`, 1 Hz). All names are relative: `--robots` puts
them under each robot's namespace.
"""

from __future__ import annotations

import math

import numpy as np
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point, Point32, PolygonStamped
from nav_msgs.msg import OccupancyGrid
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from rover_web.ros import qos

from .frames import BASE_FRAME, LASER, ODOM_FRAME, beam_directions, compose, invert, laser_origin
from .sensors import Floorplan, footprint, window

RANGE_MAX_M = 12.0
LOCAL_SIZE_M = 6.0
FOOTPRINT_HALF_M = 0.18


class Perception:
    def __init__(self, node, floorplan: Floorplan, waypoints, beams: int = 360, scan_hz: float = 10.0):
        from sensor_msgs.msg import LaserScan

        self.node = node
        self.plan = floorplan
        self.waypoints = list(waypoints)
        self._scan_class = LaserScan
        self.angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
        self.costs = floorplan.costs()
        self.scan_pub = node.create_publisher(LaserScan, "scan", qos.profile("sensor_data"))
        self.global_pub = node.create_publisher(OccupancyGrid, "global_costmap/costmap", qos.profile("latched"))
        self.local_pub = node.create_publisher(OccupancyGrid, "local_costmap/costmap", qos.profile("latched"))
        self.footprint_pub = node.create_publisher(PolygonStamped, "global_costmap/published_footprint", 1)
        self.markers_pub = node.create_publisher(MarkerArray, "visualization_marker_array", 10)
        node.create_timer(1.0 / scan_hz, self.publish_scan)
        node.create_timer(10.0, self.publish_global)
        node.create_timer(1.0, self.publish_local)
        node.create_timer(0.2, self.publish_footprint)
        node.create_timer(1.0, self.publish_markers)
        self.publish_global()

    def _header(self, msg, frame_id: str):
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = frame_id
        return msg

    def publish_scan(self) -> None:
        d = self.node.drive
        msg = self._scan_class()
        msg.header.stamp = self.node.last_stamp  # the odometry (and TF) of the pose it is cast from
        msg.header.frame_id = LASER.frame
        msg.angle_min, msg.angle_increment = float(self.angles[0]), float(self.angles[1] - self.angles[0])
        msg.angle_max = float(self.angles[-1])
        msg.range_min, msg.range_max = 0.05, RANGE_MAX_M
        x, y, heading = laser_origin((d.x, d.y, d.yaw))
        msg.ranges = self.plan.raycast(x, y, heading, beam_directions(self.angles), RANGE_MAX_M).tolist()
        self.scan_pub.publish(msg)

    def _grid(self, cells: np.ndarray, origin, frame_id: str = "map") -> OccupancyGrid:
        msg = self._header(OccupancyGrid(), frame_id)
        msg.info.resolution = self.plan.resolution
        msg.info.height, msg.info.width = cells.shape
        msg.info.origin.position.x, msg.info.origin.position.y = float(origin[0]), float(origin[1])
        msg.info.origin.orientation.z, msg.info.origin.orientation.w = math.sin(origin[2] / 2), math.cos(origin[2] / 2)
        msg.data = cells.ravel().tobytes()
        return msg

    def publish_global(self) -> None:
        self.global_pub.publish(self._grid(self.costs, (self.plan.origin_x, self.plan.origin_y, 0.0)))

    def publish_local(self) -> None:
        d = self.node.drive
        cells, ox, oy = window(self.costs, self.plan, d.x, d.y, LOCAL_SIZE_M)
        # The window is cut from the map-aligned floorplan; in odom its origin is turned by odom's yaw.
        origin = compose(invert(self.node.localisation.map_t_odom), (ox, oy, 0.0))
        self.local_pub.publish(self._grid(cells, origin, ODOM_FRAME))

    def publish_footprint(self) -> None:
        msg = self._header(PolygonStamped(), BASE_FRAME)
        msg.polygon.points = [Point32(x=float(x), y=float(y)) for x, y in footprint(0.0, 0.0, 0.0, FOOTPRINT_HALF_M)]
        self.footprint_pub.publish(msg)

    def publish_markers(self) -> None:
        array = MarkerArray()
        violet, white = ColorRGBA(r=0.82, g=0.66, b=1.0, a=0.9), ColorRGBA(r=1.0, g=1.0, b=1.0, a=1.0)
        for i, w in enumerate(self.waypoints):
            array.markers.append(self._marker("waypoints", i, Marker.SPHERE, "map", (w.x, w.y), 0.4, violet))
            label = self._marker("labels", i, Marker.TEXT_VIEW_FACING, "map", (w.x, w.y + 0.5), 0.4, white)
            label.text = w.name
            array.markers.append(label)
        if len(self.waypoints) > 1:
            route = self._marker("route", 0, Marker.LINE_STRIP, "map", (0.0, 0.0), 0.06,
                                 ColorRGBA(r=0.2, g=0.8, b=0.9, a=0.7))
            route.points = [Point(x=w.x, y=w.y) for w in self.waypoints]
            array.markers.append(route)
        heading = self._marker("heading", 0, Marker.ARROW, "base_link", (0.0, 0.0), 1.0,
                               ColorRGBA(r=1.0, g=0.85, b=0.1, a=0.9))
        heading.scale.y = heading.scale.z = 0.08
        heading.lifetime = Duration(sec=2)
        array.markers.append(heading)
        self.markers_pub.publish(array)

    def _marker(self, ns: str, marker_id: int, kind: int, frame_id: str, xy, size: float, color) -> Marker:
        m = self._header(Marker(), frame_id)
        m.ns, m.id, m.type, m.action = ns, marker_id, kind, Marker.ADD
        m.pose.position.x, m.pose.position.y = float(xy[0]), float(xy[1])
        m.pose.orientation.w = 1.0
        m.scale.x = m.scale.y = m.scale.z = size
        m.color = color
        return m
