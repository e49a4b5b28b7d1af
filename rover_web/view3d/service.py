"""The 3D view of one robot: its description (from /robot_description or a file), the poses of every TF
frame in its base frame at a tick, its point cloud thinned and packed once per message, its markers.

Everything a viewer gets is computed once and shared: the poses go out on the `view3d` SSE channel
(conflated: a slow viewer skips ticks), the cloud is one binary frame kept with a sequence number
that viewers fetch (routes.py), markers on the `view3d_markers` channel.
"""

from __future__ import annotations

import logging
import math
import threading
import time

from rover_web.core.state import Rover
from rover_web.placement import MapPlacer, Unplaceable
from rover_web.web.api_messages import Text, said, with_wire

from . import cloud, poses
from .markers import BadMarker, Markers3d
from .meshes import package_uri
from .urdf_model import UrdfError, parse

log = logging.getLogger(__name__)

CHANNELS = ("view3d", "view3d_robot", "view3d_markers")
MARKERS_MAX_HZ = 10.0
CLOUD_WATCHED_S = 5.0  # a cloud is read while a viewer asked for one this recently


class Counted:
    """receive() and skip(reason) for overlays/bounds.py's `bounded`, into a counts dict of ours."""

    def __init__(self, counts: dict, receive: bool = True):
        self._counts, self._receive = counts, receive

    def receive(self) -> None:
        if self._receive:
            self._counts["received"] = self._counts.get("received", 0) + 1

    def skip(self, reason: str) -> None:
        skipped = self._counts.setdefault("skipped", {})
        skipped[reason] = skipped.get(reason, 0) + 1
NAMES_EVERY_S = 1.0


class View3dService:
    def __init__(self, rover: Rover):
        config = rover.config
        self.rover = rover
        self.hub = rover.hub
        self.description_topic = config["ROVER_WEB_ROBOT_DESCRIPTION_TOPIC"]
        self.urdf_file = config["ROVER_WEB_URDF_FILE"]
        self.cloud_topic = config["ROVER_WEB_POINTCLOUD_TOPIC"]
        self.markers_topic = config["ROVER_WEB_MARKERS_TOPIC"]
        self.cloud_max_points = config["ROVER_WEB_POINTCLOUD_MAX_POINTS"]
        self.pose_hz = config["ROVER_WEB_VIEW3D_POSE_HZ"]
        self.base_frame = config["ROVER_WEB_BASE_FRAME"]
        self.map_frame = config["ROVER_WEB_MAP_FRAME"]
        self.odom_frame = config["ROVER_WEB_ODOM_FRAME"]
        self._lock = threading.Lock()
        self._robot: dict = {"state": "waiting", "source": None, "message": self._waiting_message()}
        self._robot_seq = 0
        self._cloud_cond = threading.Condition()
        self._cloud_raw: cloud.Cloud | None = None
        self._cloud_frame: bytes | None = None
        self._cloud_frame_seq = 0
        self._thin_lock = threading.Lock()
        self._last_voxel = 0.0  # the voxel that fitted the last cloud: the next one's first guess
        self._cloud_seq = 0
        self._cloud_counts = {"received": 0, "sent": 0, "skipped": {}}
        self._markers = Markers3d()
        self._markers_lock = threading.Lock()
        self.markers_skipped: dict[str, int] = {}  # by reason (markers.py)
        self._markers_counts: dict = {"skipped": self.markers_skipped}
        self.markers_bound = Counted(self._markers_counts)
        self.cloud_bound = Counted(self._cloud_counts)
        self.description_counts = Counted({}, receive=False)
        self._cloud_asked_at = -CLOUD_WATCHED_S  # monotonic time of the last cloud request
        self._names: list[str] = []
        self._names_at = 0.0
        self.tf = None  # the tf feature's TfBuffer, set by init_app
        self.tf_missing: Text | None = None  # why TF cannot be heard (no tf2_msgs), or None

    def _waiting_message(self) -> Text:
        if self.urdf_file:
            return said("reading %(file)s", file=self.urdf_file)
        return said("waiting for %(topic)s (std_msgs/String, transient local)", topic=self.description_topic)

    # --- the robot's description ---

    def on_description(self, text: str, source: str) -> None:
        """Parse once per description; a bad one is kept with its line so the page can say what is wrong."""
        try:
            model = parse(text)
        except UrdfError as exc:
            robot = {"state": "error", "source": source, "error": exc.as_dict()}
        else:
            meshes = []
            for uri in model.meshes:
                found = package_uri(uri)
                meshes.append({"uri": uri, "url": f"api/3d/mesh/{found[0]}/{found[1]}" if found else None})
            robot = {"state": "ok", "source": source, "name": model.name, "root": model.root, "links": model.links,
                     "joints": model.joints, "meshes": meshes, "urdf": text}
        with self._lock:
            self._robot_seq += 1
            robot["seq"] = self._robot_seq
            self._robot = robot
        self.hub.publish("view3d_robot", {"seq": robot["seq"], "state": robot["state"]})

    def load_file(self) -> None:
        try:
            with open(self.urdf_file, encoding="utf-8") as f:
                text = f.read()
        except (OSError, UnicodeDecodeError) as exc:
            with self._lock:
                self._robot_seq += 1
                self._robot = {"state": "error", "source": self.urdf_file, "seq": self._robot_seq,
                               "error": with_wire({"message": said("cannot read %(file)s: %(why)s",
                                                                   file=self.urdf_file, why=str(exc)),
                                                   "line": None, "column": None})}
            return
        self.on_description(text, self.urdf_file)

    def robot(self) -> dict:
        with self._lock:
            return with_wire(dict(self._robot, base_frame=self.base_frame, map_frame=self.map_frame,
                                  odom_frame=self.odom_frame, tf=self.tf is not None and not self.tf_missing,
                                  tf_missing=self.tf_missing,
                                  pose_hz=self.pose_hz, cloud_topic=self.cloud_topic or None,
                                  markers_topic=self.markers_topic or None,
                                  markers_skipped=dict(self.markers_skipped), cloud=self.cloud_counts()))

    # --- poses, once per tick ---

    def tick(self) -> None:
        # No open stream asked for the poses: nobody could be shown them, so none are looked up.
        if self.tf is None or self.hub.watchers("view3d") == 0:
            return
        now = time.monotonic()
        if now >= self._names_at:  # the tree's snapshot is the costly part: its names once a second
            self._names = poses.frame_names(self.tf)
            self._names_at = now + NAMES_EVERY_S
        names = self._names
        if not names:
            return
        self.hub.publish("view3d", {"base": self.base_frame, "t": time.time(),
                                    "frames": poses.in_base(self.tf, self.base_frame, names)})

    # --- point cloud ---

    def on_cloud(self, read) -> None:
        """Keep the newest cloud as read (msgs.point_cloud, called here so a bad one is counted). Thinning
        waits for a viewer to ask (cloud_after): it is the slow part, kept off the executor, and a cloud
        nobody watches costs no thinning."""
        counts = self._cloud_counts
        counts["received"] += 1
        try:
            value = read()
        except cloud.BadCloud as exc:
            reason = str(exc).split(":")[0]
            counts["skipped"][reason] = counts["skipped"].get(reason, 0) + 1
            return
        with self._cloud_cond:
            self._cloud_seq += 1
            self._cloud_raw = value
            self._cloud_cond.notify_all()

    def _thin(self, value: cloud.Cloud, seq: int) -> bytes:
        xyz, intensity, voxel = cloud.voxel_thin(value.xyz, self.cloud_max_points, value.intensity,
                                                 guess_m=self._last_voxel)
        self._last_voxel = voxel
        header = {"seq": seq, "frame_id": value.frame_id, "stamp": value.stamp, "source_points": value.source_points,
                  "voxel_m": round(voxel, 4), "topic": self.cloud_topic}
        placed = self._placed_at(value.frame_id, value.stamp)
        if placed:
            header["at_stamp"] = placed
        if len(xyz):
            low, high = xyz.min(axis=0), xyz.max(axis=0)
            header["extent"] = [[round(float(v), 4) for v in low], [round(float(v), 4) for v in high]]
            if intensity is not None:
                header["intensity_range"] = [float(intensity.min()), float(intensity.max())]
        self._cloud_counts["sent"] += 1
        return cloud.encode(header, xyz, intensity)

    def _placed_at(self, frame: str, stamp: float) -> dict:
        """The cloud's frame in each fixed frame the page offers, at the cloud's stamp (tf2 interpolates),
        so a moving robot's cloud lands where it was taken; the page falls back to the latest pose."""
        if self.tf is None or stamp <= 0:
            return {}
        placed = {}
        for fixed in {self.map_frame, self.odom_frame, self.base_frame}:
            try:
                t = self.tf.lookup(fixed, frame, int(stamp * 1e9))
            except Exception:  # TfError: not connected, or the stamp is outside the cache
                continue
            placed[fixed] = [round(float(v), 6) for v in (*t.translation, *t.rotation)]
        return placed

    def cloud_after(self, after: int, wait_s: float, ended: threading.Event | None = None
                    ) -> tuple[int, bytes | None]:
        """The newest frame if its sequence is past `after`, waiting up to wait_s for one; (seq, None) if none.
        The first viewer to ask for a new cloud thins it (once per cloud, for all). `ended`: set (with
        end_waits) when the request's credential is revoked, to stop waiting at once."""
        self._cloud_asked_at = time.monotonic()
        deadline = self._cloud_asked_at + wait_s
        with self._cloud_cond:
            # a restarted server's sequence starts again: a viewer ahead of it gets the newest at once
            while self._cloud_raw is None or after == self._cloud_seq:
                left = deadline - time.monotonic()
                if left <= 0 or self.rover.stopping.is_set() or (ended is not None and ended.is_set()):
                    return self._cloud_seq, None
                self._cloud_cond.wait(min(left, 0.5))
            seq, raw = self._cloud_seq, self._cloud_raw
        # Thinned outside the condition's lock, so the subscription callback never waits for it.
        with self._thin_lock:
            if self._cloud_frame_seq < seq:
                self._cloud_frame = self._thin(raw, seq)
                self._cloud_frame_seq = seq
            return self._cloud_frame_seq, self._cloud_frame

    def cloud_watched(self) -> bool:
        """Whether a viewer asked for a cloud lately: the subscription deserializes only then."""
        return time.monotonic() - self._cloud_asked_at < CLOUD_WATCHED_S

    def end_waits(self, ended: threading.Event) -> None:
        """Wake the waiting requests so the one whose `ended` is set returns (its credential ended)."""
        ended.set()
        with self._cloud_cond:
            self._cloud_cond.notify_all()

    def cloud_counts(self) -> dict:
        return {**self._cloud_counts, "skipped": dict(self._cloud_counts["skipped"]), "seq": self._cloud_seq}

    # --- markers ---

    def on_markers(self, markers: list[dict]) -> None:
        now = time.monotonic()
        lookups: dict[tuple[str, float], dict | BadMarker] = {}  # one set of lookups per frame and stamp of the array

        def place(frame: str, stamp: float) -> dict:
            key = (frame, stamp)
            if key not in lookups:
                try:
                    lookups[key] = self._marker_at(frame, stamp)
                except BadMarker as exc:
                    lookups[key] = exc
            found = lookups[key]
            if isinstance(found, BadMarker):
                raise found
            return found

        with self._markers_lock:
            for marker in markers:
                try:
                    self._markers.apply(marker, now, place if self.tf is not None else None)
                except BadMarker as exc:
                    reason = str(exc)
                    self.markers_skipped[reason] = self.markers_skipped.get(reason, 0) + 1
            payload = self._markers.payload()
        self.hub.publish_throttled("view3d_markers", {"markers": payload}, MARKERS_MAX_HZ)

    def _marker_at(self, frame: str, stamp: float) -> dict:
        """A marker's frame at its stamp in each fixed frame, as tf2 would place it (interpolated; a stamp
        a little ahead of the newest transform takes the newest, placement.py); {} while TF has not
        heard of the frame (the page then uses its latest pose, once there is one); BadMarker
        ("tf_extrapolation_past", ...) when TF knows the frame but not at that time, as RViz refuses it."""
        at: dict[str, list[float]] = {}
        refused = None
        for fixed in {self.map_frame, self.odom_frame, self.base_frame}:
            try:
                t = MapPlacer(self.tf, fixed).lookup(frame, stamp)
            except Unplaceable as exc:
                refused = str(exc)
                continue
            if t is not None:
                values = (*t.translation, *t.rotation)
                if all(math.isfinite(v) for v in values):
                    at[fixed] = [round(float(v), 6) for v in values]
        if not at and refused:
            raise BadMarker(refused)
        return at

    def expire_markers(self) -> None:
        with self._markers_lock:
            if not self._markers.expire(time.monotonic()):
                return
            payload = self._markers.payload()
        self.hub.publish_throttled("view3d_markers", {"markers": payload}, MARKERS_MAX_HZ)
