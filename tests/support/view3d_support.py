"""What the 3D view's tests share: URDFs, a temporary ament prefix with a package share, STL files."""

from __future__ import annotations

import struct
from pathlib import Path

# base_link: a blue box; arm: a red box 1 m long on a revolute joint about z at the top of the base,
# reaching along the arm's +x; mast: a mesh from the test package.
ROBOT_URDF = """<?xml version="1.0"?>
<robot name="testbot">
  <link name="base_link">
    <visual><geometry><box size="0.6 0.6 0.2"/></geometry>
      <material name="blue"><color rgba="0 0 1 1"/></material></visual>
  </link>
  <link name="arm">
    <visual><origin xyz="0.5 0 0" rpy="0 0 0"/><geometry><box size="1.0 0.2 0.1"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual>
  </link>
  <link name="mast">
    <visual><geometry><mesh filename="package://testbot_description/meshes/mast.stl"/></geometry>
      <material name="green"><color rgba="0 1 0 1"/></material></visual>
  </link>
  <joint name="arm_joint" type="revolute">
    <parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 0.15" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.14" upper="3.14" effort="1" velocity="1"/>
  </joint>
  <joint name="mast_joint" type="fixed">
    <parent link="base_link"/><child link="mast"/><origin xyz="-0.2 0 0.1" rpy="0 0 0"/>
  </joint>
</robot>
"""

BAD_URDF = """<?xml version="1.0"?>
<robot name="bad">
  <link name="base_link"/>
  <link name="arm"/>
  <joint name="arm_joint" type="revolute">
    <parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 zero"/>
  </joint>
</robot>
"""
BAD_URDF_LINE = 7


def stl_box(size: float = 0.1, height: float = 0.5) -> bytes:
    """A binary STL of a box `size` wide and `height` tall standing on z=0 (12 triangles)."""
    s, h = size / 2, height
    v = [(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0), (-s, -s, h), (s, -s, h), (s, s, h), (-s, s, h)]
    faces = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5),
             (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    out = bytearray(b"\0" * 80) + struct.pack("<I", len(faces))
    for a, b, c in faces:
        u = [v[b][k] - v[a][k] for k in range(3)]
        w = [v[c][k] - v[a][k] for k in range(3)]
        n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
        length = sum(x * x for x in n) ** 0.5 or 1.0
        out += struct.pack("<3f", *(x / length for x in n))
        for i in (a, b, c):
            out += struct.pack("<3f", *v[i])
        out += b"\0\0"
    return bytes(out)


def ament_prefix(root: Path, package: str = "testbot_description") -> Path:
    """A prefix with one package in the ament index and a mesh in its share folder, plus a file outside
    it and a symlink in the share folder that leads to that file."""
    prefix = root / "prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / package).write_text("")
    share = prefix / "share" / package
    (share / "meshes").mkdir(parents=True)
    (share / "meshes" / "mast.stl").write_bytes(stl_box())
    secret = root / "secret.stl"
    secret.write_bytes(stl_box(0.3))
    (share / "meshes" / "escape.stl").symlink_to(secret)
    return prefix
