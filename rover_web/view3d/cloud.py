"""Point clouds made small enough for a browser: sensor_msgs/PointCloud2 read with numpy, thinned on a
voxel grid to at most a bound, and packed as one binary frame every viewer is sent as is. Pure.

The frame: a little-endian u32 with the length of a JSON header, the header (padded with spaces to
a multiple of 4 bytes), then `count` x,y,z float32 triples, then, when the header says so, `count`
float32 intensities. One encoding per message, shared by every viewer.
"""

from __future__ import annotations

import json
import math
import struct
from dataclasses import dataclass

import numpy as np

# sensor_msgs/PointField datatypes
_DTYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
MAX_SOURCE_POINTS = 4_000_000
MAGIC_VERSION = 1


class BadCloud(ValueError):
    pass


@dataclass
class Cloud:
    frame_id: str
    stamp: float
    xyz: np.ndarray                 # (n, 3) float32, finite
    intensity: np.ndarray | None    # (n,) float32 or None
    source_points: int = 0


def read(frame_id: str, stamp: float, height: int, width: int, fields: list[tuple[str, int, int, int]],
         point_step: int, row_step: int, is_bigendian: bool, data: bytes) -> Cloud:
    """A PointCloud2's x, y, z (and intensity) as arrays; fields are (name, offset, datatype, count)."""
    n = height * width
    if n > MAX_SOURCE_POINTS:
        raise BadCloud(f"too_large: {n} points (at most {MAX_SOURCE_POINTS})")
    by_name = {name: (offset, datatype) for name, offset, datatype, _count in fields}
    if not all(k in by_name for k in "xyz"):
        raise BadCloud("no_xyz: the cloud has no x, y and z fields")
    if point_step <= 0 or row_step < width * point_step or len(data) < row_step * height:
        raise BadCloud("bad_layout: point_step, row_step and the data's length disagree")
    order = ">" if is_bigendian else "<"
    names, formats, offsets = [], [], []
    for name in ("x", "y", "z", "intensity"):
        if name not in by_name:
            continue
        offset, datatype = by_name[name]
        if datatype not in _DTYPES or offset + np.dtype(_DTYPES[datatype]).itemsize > point_step:
            raise BadCloud(f"bad_field: {name} has datatype {datatype} at offset {offset}")
        names.append(name)
        formats.append(order + _DTYPES[datatype])
        offsets.append(offset)
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": point_step})
    rows = np.frombuffer(data, dtype=np.uint8, count=row_step * height).reshape(height, row_step)
    points = np.ascontiguousarray(rows[:, :width * point_step]).view(dtype).reshape(-1)
    xyz = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(np.float32, copy=False)
    intensity = points["intensity"].astype(np.float32) if "intensity" in names else None
    keep = np.isfinite(xyz).all(axis=1)  # NaN is "no return" in an organised cloud
    if intensity is not None:
        keep &= np.isfinite(intensity)
    if not keep.all():
        xyz = xyz[keep]
        intensity = intensity[keep] if intensity is not None else None
    return Cloud(frame_id, stamp, xyz, intensity, n)


def voxel_thin(xyz: np.ndarray, max_points: int, intensity: np.ndarray | None = None, guess_m: float = 0.0
               ) -> tuple[np.ndarray, np.ndarray | None, float]:
    """At most `max_points` points, one per occupied voxel (any one in it), the voxel grown until
    they fit; the bounding box stays within one voxel of the original. Returns (xyz, intensity, voxel_m).
    `guess_m`: the voxel that fitted the sensor's last cloud, a better start than any formula (one
    sensor's clouds look alike), so most clouds take one pass."""
    n = len(xyz)
    if n <= max_points:
        return xyz, intensity, 0.0
    low = xyz.min(axis=0)
    spans = np.maximum(xyz.max(axis=0) - low, 1e-3).astype(np.float64)
    # First guess: the points fill their box. A cloud on surfaces (walls, ground) fills fewer voxels,
    # so the guess is refined from the count it gives, keeping the finest grid that fits the bound.
    voxel = guess_m if guess_m > 0 else float(np.prod(spans) / max_points) ** (1 / 3)
    best = None
    for _ in range(6):
        keys = np.floor((xyz - low) / np.float32(voxel)).astype(np.int64)
        dims = keys.max(axis=0) + 1
        flat = (keys[:, 0] * dims[1] + keys[:, 1]) * dims[2] + keys[:, 2]
        first = _one_per_voxel(flat)
        count = len(first)
        if count <= max_points:
            best = (first, voxel)
            if count >= 0.7 * max_points:
                break
            voxel *= max(0.5, math.sqrt(count / max_points))  # too coarse: finer
        else:
            voxel *= min(3.0, max(1.1, math.sqrt(count / max_points)))
    if best is None:  # still over after every step: a hard bound, evenly spaced in the sensor's order
        first, voxel = np.linspace(0, n - 1, max_points).astype(np.int64), voxel
    else:
        first, voxel = best
    first.sort()  # keep the sensor's order (scan lines stay lines)
    return xyz[first], (intensity[first] if intensity is not None else None), voxel


def _one_per_voxel(keys: np.ndarray) -> np.ndarray:
    """The index of one point in each distinct voxel key. Any point of a voxel will do, so an unstable
    sort (five times faster than np.unique's stable one on 100,000 keys) and the first of each run."""
    order = np.argsort(keys)
    ordered = keys[order]
    starts = np.empty(len(keys), dtype=bool)
    starts[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=starts[1:])
    return order[starts]


def encode(header: dict, xyz: np.ndarray, intensity: np.ndarray | None) -> bytes:
    head = dict(header, count=len(xyz), intensity=intensity is not None, version=MAGIC_VERSION)
    text = json.dumps(head, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)  # the float arrays start 4-byte aligned
    parts = [struct.pack("<I", len(text)), text, np.ascontiguousarray(xyz, dtype="<f4").tobytes()]
    if intensity is not None:
        parts.append(np.ascontiguousarray(intensity, dtype="<f4").tobytes())
    return b"".join(parts)


def decode(frame: bytes) -> tuple[dict, np.ndarray, np.ndarray | None]:
    """The inverse of encode (tests and the bench read frames with it)."""
    (length,) = struct.unpack_from("<I", frame)
    header = json.loads(frame[4:4 + length])
    count = header["count"]
    start = 4 + length
    xyz = np.frombuffer(frame, dtype="<f4", count=count * 3, offset=start).reshape(count, 3)
    intensity = None
    if header["intensity"]:
        intensity = np.frombuffer(frame, dtype="<f4", count=count, offset=start + count * 12)
    return header, xyz, intensity
