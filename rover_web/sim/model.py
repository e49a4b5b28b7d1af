"""The simulated rover's robot description (URDF), published on /robot_description as
robot_state_publisher serves it (std_msgs/String, transient local), so the 3D view draws a model.

Built from the same mounts the simulator sends on /tf_static (frames.py), so the model's sensor
links sit where TF puts them: a body the size of the footprint (perception.py), four wheels, the
laser (upside down), the GPS antenna and the camera. Every joint is fixed: the simulator's wheels
are not joints it reports (it publishes no /joint_states), and a fixed joint needs no TF of its own.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

from .frames import BASE_FRAME, MOUNTS, Mount
from .perception import FOOTPRINT_HALF_M

BODY_HEIGHT_M = 0.12
BODY_LIFT_M = 0.08  # the body's bottom above the ground (the wheels' radius)
WHEEL_RADIUS_M = 0.08
WHEEL_WIDTH_M = 0.04

_COLOURS = {"body": "0.85 0.55 0.1 1", "wheel": "0.15 0.15 0.15 1", "sensor": "0.2 0.45 0.85 1"}


def _link(name: str, geometry: str, xyz: str = "0 0 0", rpy: str = "0 0 0", colour: str = "sensor") -> str:
    return (f"  <link name={quoteattr(name)}><visual><origin xyz={quoteattr(xyz)} rpy={quoteattr(rpy)}/>"
            f"<geometry>{geometry}</geometry><material name={quoteattr(colour)}/></visual></link>\n")


def _fixed(parent: str, child: str, xyz: tuple[float, float, float], rpy: tuple[float, float, float]) -> str:
    return (f"  <joint name={quoteattr(f'{parent}_to_{child}')} type=\"fixed\"><parent link={quoteattr(parent)}/>"
            f"<child link={quoteattr(child)}/><origin xyz=\"{xyz[0]:g} {xyz[1]:g} {xyz[2]:g}\" "
            f"rpy=\"{rpy[0]:g} {rpy[1]:g} {rpy[2]:g}\"/></joint>\n")


def rover_urdf(mounts: tuple[Mount, ...] = MOUNTS) -> str:
    side = 2 * FOOTPRINT_HALF_M
    parts = ['<?xml version="1.0"?>\n<robot name="sim_rover">\n']
    parts += [f'  <material name="{name}"><color rgba="{rgba}"/></material>\n' for name, rgba in _COLOURS.items()]
    parts.append(_link(BASE_FRAME, f'<box size="{side:g} {side * 0.8:g} {BODY_HEIGHT_M:g}"/>',
                       xyz=f"0 0 {BODY_LIFT_M + BODY_HEIGHT_M / 2:g}", colour="body"))
    for name, x, y in (("front_left", 1, 1), ("front_right", 1, -1), ("rear_left", -1, 1), ("rear_right", -1, -1)):
        wheel = f"wheel_{name}"
        # A cylinder's axis is its z: rolled a quarter turn, it stands as a wheel on the y axis.
        parts.append(_link(wheel, f'<cylinder radius="{WHEEL_RADIUS_M:g}" length="{WHEEL_WIDTH_M:g}"/>',
                           rpy="1.5708 0 0", colour="wheel"))
        parts.append(_fixed(BASE_FRAME, wheel, (x * FOOTPRINT_HALF_M * 0.7, y * (side * 0.4 + WHEEL_WIDTH_M / 2),
                                                WHEEL_RADIUS_M), (0.0, 0.0, 0.0)))
    for mount in mounts:
        parts.append(_link(mount.frame, '<box size="0.06 0.06 0.04"/>' if mount.frame != "gps"
                           else '<cylinder radius="0.015" length="0.1"/>'))
        parts.append(_fixed(BASE_FRAME, mount.frame, (mount.x, mount.y, mount.z), (mount.roll, mount.pitch, mount.yaw)))
    parts.append("</robot>\n")
    return "".join(parts)


class DescriptionPublisher:
    """/robot_description once, latched, on the robot's node (its namespace's topic)."""

    def __init__(self, node):
        from std_msgs.msg import String

        from rover_web.ros import qos

        self.pub = node.create_publisher(String, "robot_description", qos.profile("latched"))
        self.pub.publish(String(data=rover_urdf()))
