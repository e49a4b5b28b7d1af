"""A recording's frames: a TfBuffer fed from the file's TFMessage topics, as the live one is fed by ROS.

The replay view (rover_web/recording/replay_routes.py) asks for the tree or a lookup at a time t of
the recording. The buffer gets what a live TransformListener would hold at t: every static
transform logged up to t, and the dynamic ones logged in the cache window before it. Each message's
bytes are read with wire.py (no tf2_msgs package needed); one that is not plain CDR is decoded by
mcap-ros2-support from the file's own schema instead.

Which topics: every tf2_msgs/msg/TFMessage topic of the file, a name ending in `tf_static` static
and any other dynamic, so a robot's namespaced /boat/tf, rosbag2's /tf and /tf_static, and a file
from elsewhere whose TF is on another name all show.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

from . import wire
from .buffer import TfBuffer

TF_TYPE = "tf2_msgs/msg/TFMessage"
MAX_TRANSFORMS = 200_000  # one question reads at most this many (1,000 a second over a 10 s window is 10,000)
CACHED = 8


def tf_topics(index) -> dict[str, bool]:
    """topic -> static, for every TFMessage topic with messages."""
    return {topic: topic.rstrip("/").endswith("tf_static")
            for topic, info in index.topics().items() if info["type"] == TF_TYPE}


def _transforms(index, message) -> list[wire.Stamped]:
    try:
        return wire.tf_message(message.data)
    except wire.NotPlainCdr:
        decoded = index.decode(message)
        if decoded is None:
            return []
        try:
            return [wire.Stamped(t.header.frame_id, t.child_frame_id,
                                 t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec,
                                 (t.transform.translation.x, t.transform.translation.y, t.transform.translation.z),
                                 (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
                                  t.transform.rotation.w))
                    for t in decoded.transforms]
        except AttributeError:
            return []  # a TFMessage of another shape


def buffer_at(index, t_ns: int, cache_s: float) -> tuple[TfBuffer, dict]:
    """The buffer a listener would hold at t_ns, and what went into it."""
    topics = tf_topics(index)
    buffer = TfBuffer(cache_s)
    read = {"messages": 0, "transforms": 0, "undecodable": 0, "truncated": False}
    static = [t for t, s in topics.items() if s]
    dynamic = [t for t, s in topics.items() if not s]
    for names, start, is_static in ((static, None, True), (dynamic, t_ns - int(cache_s * 1e9), False)):
        if not names:
            continue
        batch = sorted(index.messages(names, start, t_ns), key=lambda cm: cm[1].log_time)
        for _channel, message in batch:
            transforms = _transforms(index, message)
            if not transforms:
                read["undecodable"] += 1
                continue
            read["messages"] += 1
            for tf in transforms:
                if read["transforms"] >= MAX_TRANSFORMS:
                    read["truncated"] = True
                    break
                read["transforms"] += 1
                buffer.set_transform(tf.parent, tf.child, tf.translation, tf.rotation, tf.stamp_ns, static=is_static)
    return buffer, {"topics": topics, "read": read}


_memo: OrderedDict = OrderedDict()
_memo_lock = threading.Lock()


def cached_buffer_at(index, t_ns: int, cache_s: float) -> tuple[TfBuffer, dict]:
    """buffer_at, kept for the last few (file, t) questions: a lookup form asks several times at one t."""
    stat = index.path.stat()
    key = (str(index.path), stat.st_size, stat.st_mtime_ns, t_ns, cache_s)
    with _memo_lock:
        if key in _memo:
            _memo.move_to_end(key)
            return _memo[key]
    value = buffer_at(index, t_ns, cache_s)
    with _memo_lock:
        _memo[key] = value
        while len(_memo) > CACHED:
            _memo.popitem(last=False)
    return value


def tree_at(index, t_ns: int, cache_s: float, stale_s: float) -> dict:
    """The /api/tf shape for the recording at t_ns (ages and warnings judged at t_ns)."""
    buffer, info = cached_buffer_at(index, t_ns, cache_s)
    tree = buffer.frames(t_ns, stale_s=stale_s)
    return {"available": True, "missing": None, "t": t_ns / 1e9, "start": (index.start_ns or 0) / 1e9,
            "end": (index.end_ns or 0) / 1e9, "tf_topics": info["topics"], "read": info["read"], **tree}
