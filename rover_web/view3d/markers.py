"""visualization_msgs markers kept in 3D, as RViz keeps them: added or replaced by (ns, id), removed by
DELETE, all by DELETEALL, gone when their lifetime runs out. Each keeps its own frame and, as tf2 and
RViz place a marker, where that frame was at the marker's stamp (`at_stamp`: its pose in each fixed
frame the page offers, from a `place(frame, stamp)` the service gives); a marker stamped 0 or
`frame_locked` has none, and the page places it with its frame's latest pose (poses.py). Pure."""

from __future__ import annotations

import math
from collections.abc import Callable

KINDS = {0: "arrow", 1: "cube", 2: "sphere", 3: "cylinder", 4: "line_strip", 5: "line_list", 6: "cube_list",
         7: "sphere_list", 8: "points", 9: "text", 10: "mesh", 11: "triangle_list"}
ADD, DELETE, DELETEALL = 0, 2, 3


class BadMarker(ValueError):
    pass


class Markers3d:
    def __init__(self, max_points: int = 20000, max_markers: int = 2000):
        self.max_points, self.max_markers = max_points, max_markers
        self._markers: dict[tuple[str, int], dict] = {}
        self._expiry: dict[tuple[str, int], float] = {}

    def apply(self, marker: dict, now: float, place: Callable[[str, float], dict] | None = None) -> None:
        """`place(frame, stamp)`: the frame's pose at the stamp in each fixed frame ({} when TF cannot
        say yet: the page's latest pose), or BadMarker (tf2 refused the stamp: the marker is not kept)."""
        key = (marker["ns"], marker["id"])
        if marker["action"] == DELETEALL:
            self._markers.clear()
            self._expiry.clear()
            return
        if marker["action"] == DELETE:
            self._markers.pop(key, None)
            self._expiry.pop(key, None)
            return
        if marker["action"] != ADD:
            raise BadMarker("bad_action")
        if marker["type"] not in KINDS:
            raise BadMarker("unsupported_type")
        numbers = [*marker["pose"], *marker["scale"], *marker["color"]]
        numbers += [v for p in marker["points"] for v in p] + [v for c in marker["colors"] for v in c]
        if not all(math.isfinite(v) for v in numbers):
            raise BadMarker("not_finite")
        if len(marker["points"]) > self.max_points:
            raise BadMarker("too_many_points")
        if key not in self._markers and len(self._markers) >= self.max_markers:
            raise BadMarker("too_many_markers")
        kept = {k: marker[k] for k in ("ns", "id", "frame_id", "pose", "scale", "color", "points", "colors", "text")}
        kept["kind"] = KINDS[marker["type"]]
        stamp = marker.get("stamp", 0.0)
        if place is not None and stamp > 0 and not marker.get("frame_locked", False):
            at_stamp = place(marker["frame_id"], stamp)
            if at_stamp:
                kept["at_stamp"] = at_stamp
        if marker["type"] == 10:
            kept["mesh"] = marker["mesh_resource"]
        self._markers[key] = kept
        if marker["lifetime_s"] > 0:
            self._expiry[key] = now + marker["lifetime_s"]
        else:
            self._expiry.pop(key, None)

    def expire(self, now: float) -> bool:
        gone = [k for k, t in self._expiry.items() if t <= now]
        for key in gone:
            self._markers.pop(key, None)
            del self._expiry[key]
        return bool(gone)

    def payload(self) -> list[dict]:
        return list(self._markers.values())
