"""Every TF frame's pose in the robot's base frame, once per tick, for every viewer at once.

The page picks its fixed frame (map, odom, the robot's) among these and composes on its side:
T_fixed_X = inverse(T_base_fixed) * T_base_X, so one computation serves every fixed frame. Pure:
works on anything with TF_API.md's `lookup(target, source)` and `frames()`.
"""

from __future__ import annotations

import math


def _round(values, digits: int = 6) -> list[float]:
    return [round(float(v), digits) for v in values]


def frame_names(buffer) -> list[str]:
    """Every frame the buffer knows: each child frame and each root (a frame only ever a parent)."""
    try:
        tree = buffer.frames()
    except Exception:  # a buffer mid-change: this tick shows what the last one did
        return []
    names = list(tree.get("frames", {}))
    roots = tree.get("roots", [])
    names += [r if isinstance(r, str) else r.get("frame", "") for r in roots]
    return sorted({n for n in names if n})


def in_base(buffer, base: str, frames: list[str], max_frames: int = 500) -> dict[str, list[float] | None]:
    """{frame: [x, y, z, qx, qy, qz, qw] in `base`, or None when TF cannot say}, the latest common time."""
    out: dict[str, list[float] | None] = {}
    for frame in frames[:max_frames]:
        if frame == base:
            out[frame] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
            continue
        try:
            t = buffer.lookup(base, frame)
        except Exception:  # TfError: unknown, not connected, extrapolation; shown as missing
            out[frame] = None
            continue
        values = (*t.translation, *t.rotation)
        out[frame] = _round(values) if all(math.isfinite(v) for v in values) else None
    return out
