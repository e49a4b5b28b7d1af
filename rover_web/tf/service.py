"""TF of one robot: /tf and /tf_static into a TfBuffer, the tree for /api/tf and the `tf` channel.

Messages are taken raw, off the executor (RosRuntime.subscribe(raw=True, share=True): a thread of
its own), and read field by field (wire.py): a 200-frame robot sends 1,000 transforms a second.
Lookups are never made per viewer: other features look up once per message or per tick, and the
page gets one snapshot a second on the `tf` channel.

Without tf2_msgs (no ROS sourced, the interface packages not built) nothing is subscribed: the
buffer exists and stays empty, `available` is False and `missing` says what to install.
"""

from __future__ import annotations

import logging
import threading
import time

from rover_web.core.state import Rover
from rover_web.web.api_messages import with_wire

from . import wire
from .buffer import TfBuffer

log = logging.getLogger(__name__)

CHANNEL = "tf"
TICK_S = 1.0  # the page's refresh: ages move on even when nothing arrives


class TfService:
    def __init__(self, rover: Rover, *, missing=None, clock_ns=None, publishers=None):
        config = rover.config
        self.rover = rover
        self.buffer = TfBuffer(config["ROVER_WEB_TF_CACHE_S"])
        self.stale_s = config["ROVER_WEB_TF_STALE_S"]
        self.frames = {"map": config["ROVER_WEB_MAP_FRAME"], "odom": config["ROVER_WEB_ODOM_FRAME"],
                       "base": config["ROVER_WEB_BASE_FRAME"]}
        self.topics = {"dynamic": rover.resolve("/tf"), "static": rover.resolve("/tf_static")}
        self.missing = missing
        self._clock_ns = clock_ns or time.time_ns
        # ROS 2 does not say which node sent a message (tf2_ros calls it "Authority undetectable"):
        # the nodes publishing each topic are the candidates the page shows beside a conflict.
        self._publishers = publishers or (lambda topic: [])
        self._lock = threading.Lock()
        self.counts = {"messages": 0, "transforms": 0, "undecodable": 0}
        self.last_undecodable = ""

    @property
    def available(self) -> bool:
        return self.missing is None

    def now_ns(self) -> int:
        return self._clock_ns()

    # --- ingestion (the taker thread) ---

    def on_raw(self, raw: bytes, static: bool) -> None:
        try:
            transforms = wire.tf_message(raw)
        except wire.NotPlainCdr as exc:
            with self._lock:
                self.counts["undecodable"] += 1
                self.last_undecodable = str(exc)
            return
        self.ingest(transforms, static)

    def ingest(self, transforms, static: bool, authority: str = "") -> None:
        put = self.buffer.set_transform
        for t in transforms:
            put(t.parent, t.child, t.translation, t.rotation, t.stamp_ns, static=static, authority=authority)
        with self._lock:
            self.counts["messages"] += 1
            self.counts["transforms"] += len(transforms)

    # --- what the page and the API read ---

    def tree(self) -> dict:
        tree = self.buffer.frames(self.now_ns(), stale_s=self.stale_s)
        with self._lock:
            counts = dict(self.counts)
        publishers = {kind: self._publishers(topic) for kind, topic in self.topics.items()} if self.available else {}
        return with_wire({
            "available": self.available,
            "missing": self.missing,
            "topics": self.topics,
            "publishers": publishers,
            "settings_frames": self.frames,
            "counts": counts,
            "last_undecodable": self.last_undecodable,
            **tree,
        })

    def publish(self) -> None:
        if self.available:
            self.rover.hub.publish(CHANNEL, self.tree())
