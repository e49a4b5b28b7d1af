"""The maths of transforms on Python tuples: the quaternion product, a vector's rotation, slerp, and
Transform, a stamped rigid transform.

Hand-written rather than a library, for speed: rover_web/tf/buffer.py's docstring has the figures;
tests/unit/tf/ checks the maths against 4x4 matrices and scipy's slerp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

Quaternion = tuple[float, float, float, float]
Vector = tuple[float, float, float]
# Above this dot product (two rotations 1e-3 rad apart or closer) slerp's sin(theta) is too small to
# divide by; a normalised lerp there is within 1e-11 rad of it.
NLERP_DOT = 1.0 - 1e-7


def _qmul(a: Quaternion, b: Quaternion) -> Quaternion:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def _rotate(q: Quaternion, x: float, y: float, z: float) -> Vector:
    # v + 2w(q×v) + 2 q×(q×v): two cross products, no matrix
    qx, qy, qz, qw = q
    tx = 2.0 * (qy * z - qz * y)
    ty = 2.0 * (qz * x - qx * z)
    tz = 2.0 * (qx * y - qy * x)
    return (x + qw * tx + (qy * tz - qz * ty),
            y + qw * ty + (qz * tx - qx * tz),
            z + qw * tz + (qx * ty - qy * tx))


def compose(ta: Vector, qa: Quaternion, tb: Vector, qb: Quaternion) -> tuple[Vector, Quaternion]:
    """(ta, qa) ∘ (tb, qb): apply b, then a."""
    rx, ry, rz = _rotate(qa, tb[0], tb[1], tb[2])
    return (rx + ta[0], ry + ta[1], rz + ta[2]), _qmul(qa, qb)


def invert(t: Vector, q: Quaternion) -> tuple[Vector, Quaternion]:
    qi = (-q[0], -q[1], -q[2], q[3])
    x, y, z = _rotate(qi, t[0], t[1], t[2])
    return (-x, -y, -z), qi


def product(values: list[tuple[Vector, Quaternion]], lo: int, hi: int) -> tuple[Vector, Quaternion]:
    """values[hi-1] ∘ ... ∘ values[lo]: a frame's way up to the common ancestor, as one transform.

    The same maths as compose, written out in one loop over locals: a lookup composes up to
    ten links and the function calls were a third of its time."""
    if lo >= hi:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    (tx, ty, tz), (qx, qy, qz, qw) = values[lo]
    for i in range(lo + 1, hi):
        (ax, ay, az), (px, py, pz, pw) = values[i]  # the parent's link: applied after what we have
        # rotate (tx, ty, tz) by p, then add the parent's translation
        cx = 2.0 * (py * tz - pz * ty)
        cy = 2.0 * (pz * tx - px * tz)
        cz = 2.0 * (px * ty - py * tx)
        tx, ty, tz = (tx + pw * cx + (py * cz - pz * cy) + ax,
                      ty + pw * cy + (pz * cx - px * cz) + ay,
                      tz + pw * cz + (px * cy - py * cx) + az)
        qx, qy, qz, qw = (pw * qx + px * qw + py * qz - pz * qy,
                          pw * qy - px * qz + py * qw + pz * qx,
                          pw * qz + px * qy - py * qx + pz * qw,
                          pw * qw - px * qx - py * qy - pz * qz)
    return (tx, ty, tz), (qx, qy, qz, qw)


def slerp(a: Quaternion, b: Quaternion, r: float) -> Quaternion:
    """Spherical interpolation along the shorter arc (tf2 flips b when the dot product is negative)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    dot = ax * bx + ay * by + az * bz + aw * bw
    if dot < 0.0:
        bx, by, bz, bw, dot = -bx, -by, -bz, -bw, -dot
    if dot > NLERP_DOT:
        # nearly the same rotation: sin(theta) -> 0; a normalised lerp is within 1e-11 rad of slerp here
        x, y, z, w = ax + r * (bx - ax), ay + r * (by - ay), az + r * (bz - az), aw + r * (bw - aw)
        n = math.sqrt(x * x + y * y + z * z + w * w)
        return (x / n, y / n, z / n, w / n)
    theta = math.acos(dot)
    s = math.sin(theta)
    wa = math.sin((1.0 - r) * theta) / s
    wb = math.sin(r * theta) / s
    return (wa * ax + wb * bx, wa * ay + wb * by, wa * az + wb * bz, wa * aw + wb * bw)


def yaw_of(q: Quaternion) -> float:
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True, slots=True)
class Transform:
    """Maps points given in ``source`` into ``target`` (tf2's lookupTransform(target, source))."""

    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]  # x, y, z, w (unit)
    stamp_ns: int = 0

    @classmethod
    def identity(cls, stamp_ns: int = 0) -> Transform:
        return cls((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), stamp_ns)

    def apply(self, x: float, y: float, z: float = 0.0) -> tuple[float, float, float]:
        rx, ry, rz = _rotate(self.rotation, x, y, z)
        t = self.translation
        return (rx + t[0], ry + t[1], rz + t[2])

    def matrix(self) -> np.ndarray:
        """The 3x3 rotation matrix (for callers that transform many points themselves)."""
        x, y, z, w = self.rotation
        return np.array((
            (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
        ))

    def apply_many(self, xs, ys, zs=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        xs = np.asarray(xs, dtype=float)
        ys = np.asarray(ys, dtype=float)
        zs = np.zeros_like(xs) if zs is None else np.asarray(zs, dtype=float)
        m = self.matrix()
        t = self.translation
        return (m[0, 0] * xs + m[0, 1] * ys + m[0, 2] * zs + t[0],
                m[1, 0] * xs + m[1, 1] * ys + m[1, 2] * zs + t[1],
                m[2, 0] * xs + m[2, 1] * ys + m[2, 2] * zs + t[2])

    @property
    def yaw(self) -> float:
        return yaw_of(self.rotation)

    def inverse(self) -> Transform:
        t, q = invert(self.translation, self.rotation)
        return Transform(t, q, self.stamp_ns)

    def compose(self, other: Transform) -> Transform:
        """self ∘ other: ``other`` first. The stamp is self's."""
        t, q = compose(self.translation, self.rotation, other.translation, other.rotation)
        return Transform(t, q, self.stamp_ns)
