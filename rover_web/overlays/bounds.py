"""What one overlay message may cost before it is deserialized (issue 40, third security round).

Any DDS peer on the domain may publish on the overlay topics. The review's MarkerArray of 200,000
zero-point cubes was deserialized and converted whole (the cap counted points), grew the markers
frame to 15.7 MB an event and took the e-stop's GET to 0.43 s; a 100-million-cell OccupancyGrid was
deserialized and copied before its size was refused. So the overlay topics are subscribed raw: the
callback gets the serialized bytes, and a message longer than its topic's bound is counted
(`too_large`) and dropped before rclpy builds a Python object of it. Markers are then capped by
count before conversion (msgs.markers) and in the set kept (markers.MarkerSet.max_markers), their
`ns` and `text` truncated; scans and markers are deserialized only while a page watches them (a
costmap is kept regardless: Nav2 latches the global one, and a page opened later reads it).
"""

from __future__ import annotations

from collections.abc import Callable

KIB = 1024
MARKERS_MAX_BYTES = 1024 * KIB  # 1,000 markers of ~250 bytes and 5,000 points of 24 bytes fit in a third of it
MARKERS_MAX_COUNT = 1000  # per array converted, and in the set kept
SCAN_MAX_BYTES = 1024 * KIB  # 131,000 beams with intensities; a 3D lidar's 2D slice is a few thousand
FOOTPRINT_MAX_BYTES = 16 * KIB  # FOOTPRINT_MAX_POINTS (200) points of 12 bytes
GRID_OVERHEAD_BYTES = 4 * KIB  # header, frame_id and MapMetaData around the cells
NS_MAX = 64
TEXT_MAX = 200
FRAME_ID_MAX = 256  # a frame name; each marker carries its own into the frame sent to every page
# The markers topic has one DDS reader for the overlays and the 3D view: Fast DDS reassembles a sample
# whole in every reader before rmw can hand over its length, and rmw and rclpy then copy it twice
# (FastBuffer, the serialized message, then Python's bytes: each step holds two copies at once). Two
# readers cost a 46 MB array 135 MB at peak, one 92 MB (bench/hostile.py, BENCHMARKS.md 2026-11-29).
# Taken on the executor, as before (taker=False): converting an array of 1,000 markers for both is tens
# of milliseconds, which on the runtime's taker thread would hold back /tf and /odom behind it.
MARKERS_SHARED = {"raw": True, "share": True, "taker": False}
MARKERS_DEPTH = 10  # arrays are deltas (add, delete): a burst must not lose any


def grid_max_bytes(max_cells: int) -> int:
    return max_cells + GRID_OVERHEAD_BYTES


def bounded(counts, most_bytes: int, deserialize: Callable[[bytes], object], handle: Callable[[object], None],
            watched: Callable[[], bool] | None = None) -> Callable[[bytes], None]:
    """A raw subscription's callback: nothing while nobody watches (when `watched` is given), a
    message over `most_bytes` counted `too_large` and dropped undeserialized, others handled."""

    def on_raw(raw: bytes) -> None:
        if watched is not None and not watched():
            return
        if len(raw) > most_bytes:
            counts.receive()
            counts.skip("too_large")
            return
        handle(deserialize(raw))

    return on_raw
