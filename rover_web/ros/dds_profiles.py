"""A Fast DDS profile that frees the overlay readers' samples as soon as they are taken (issue 40).

The overlay topics are subscribed raw and a message over its byte bound is dropped before rclpy
deserializes it (overlays/bounds.py); but Fast DDS has already reassembled the whole sample and
rclpy copied it. rmw_fastrtps makes every reader's history PREALLOCATED_WITH_REALLOC: the buffer
grows to the largest sample ever received and is kept, so one hostile 40 MB MarkerArray left
40 MB in the reader's pool for good, on top of the copies made while it was taken (RSS +130-140 MB).

Fast DDS 2.14 (the Jazzy wheels) has no per-reader bound on a sample's size that a profile can
set: PREALLOCATED does refuse a larger sample before reassembly, but its size is the type's
bound, which for MarkerArray (unbounded sequences) is a few bytes, so it refused every marker
(measured: BENCHMARKS.md). What a profile can do is give the overlay readers DYNAMIC memory: each
sample's payload is allocated at its size and freed when rmw has taken it, so a hostile sample costs
its size for the moment it is taken, not forever, and the overlays' ordinary messages (kilobytes)
cost an allocation each. Camera images and every other reader keep rmw's defaults.

rmw_fastrtps (8.4.x) loads a data_reader profile named after the subscription's ROS topic name
(`/visualization_marker_array`, not the DDS name `rt/...`) but then overrides its memory policy
unless RMW_FASTRTPS_USE_QOS_FROM_XML=1, which hands every endpoint of the process to the XML: so
the file also carries default reader and writer profiles that say what rmw would have set
(PREALLOCATED_WITH_REALLOC, no data sharing, the publication mode of RMW_FASTRTPS_PUBLICATION_MODE).

Fast DDS reads the file once per process, when the first participant is created: so it is
written and pointed at before the first rclpy context (RosRuntime), and a second app in the same
process gets the first one's profiles. A user who already set a profile file, or the variable,
keeps theirs untouched (a warning says the overlays are then not covered).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable, MutableMapping
from pathlib import Path
from xml.sax.saxutils import quoteattr

log = logging.getLogger(__name__)

PROFILE_FILE = "FASTRTPS_DEFAULT_PROFILES_FILE"  # Fast DDS 2.x; 3.x reads FASTDDS_DEFAULT_PROFILES_FILE
QOS_FROM_XML = "RMW_FASTRTPS_USE_QOS_FROM_XML"
THEIRS = (PROFILE_FILE, "FASTDDS_DEFAULT_PROFILES_FILE", QOS_FROM_XML)
CWD_PROFILE = "DEFAULT_FASTRTPS_PROFILES.xml"  # Fast DDS also loads this one from the working directory
# Says the two variables above are rover_web's (a child process inherits them); not ROVER_WEB_*: the
# app refuses unknown settings of its prefix.
OURS = "FASTRTPS_PROFILES_FROM_ROVER_WEB"
FASTRTPS = "rmw_fastrtps_cpp"
FILE_NAME = "overlay_readers.xml"
PUBLISH_MODES = {"SYNCHRONOUS": "SYNCHRONOUS", "ASYNCHRONOUS": "ASYNCHRONOUS", "AUTO": None}

_written: Path | None = None  # the file this process pointed Fast DDS at


def resolve(topic: str, node_name: str) -> str:
    """The name rcl gives rmw for a topic of a node in the root namespace (the app's node)."""
    if topic.startswith("~"):
        return f"/{node_name}{topic[1:]}"
    return topic if topic.startswith("/") else "/" + topic


def prepare(topics: Iterable[str], folder: Path, node_name: str,
            environ: MutableMapping[str, str] | None = None) -> Path | None:
    """Write the profile for `topics` into `folder` and point Fast DDS at it; the file, or None
    when the middleware is not Fast DDS or the user's own profile settings are left alone."""
    global _written
    env = os.environ if environ is None else environ
    names = sorted({resolve(t, node_name) for t in topics if t})
    if not names or env.get("RMW_IMPLEMENTATION", FASTRTPS) != FASTRTPS:
        return None
    if env.get(PROFILE_FILE) and env.get(PROFILE_FILE) == env.get(OURS) and env.get(QOS_FROM_XML) == "1":
        if _written is not None and env[PROFILE_FILE] == str(_written):
            # Fast DDS has read it already: a second app in this process shares the first one's profiles.
            return _written
        # Inherited from a rover_web that started this process: not the user's, and this one writes its own.
        for name in (PROFILE_FILE, QOS_FROM_XML, OURS):
            env.pop(name)
    theirs = [name for name in THEIRS if name in env]
    if env.get("SKIP_DEFAULT_XML_FILE") != "1" and (Path.cwd() / CWD_PROFILE).exists():
        theirs.append(str(Path.cwd() / CWD_PROFILE))
    if theirs:
        log.warning("Fast DDS profiles are yours (%s): the overlay readers keep rmw's memory policy, and a "
                    "hostile oversized overlay message stays in memory after it is dropped; give the data_reader "
                    "profiles %s historyMemoryPolicy DYNAMIC (docs/ros.md)", ", ".join(theirs), ", ".join(names))
        return None
    path = folder / FILE_NAME
    try:
        folder.mkdir(parents=True, exist_ok=True)
        # Whole or not at all: another process starting now (a second worker) may be reading it.
        part = folder / f".{FILE_NAME}.{os.getpid()}"
        part.write_text(profiles_xml(names, env.get("RMW_FASTRTPS_PUBLICATION_MODE", "SYNCHRONOUS")),
                        encoding="utf-8")
        os.replace(part, path)
    except OSError as exc:  # the GUI still runs, as it did before this profile
        log.warning("could not write %s (%s): the overlay readers keep rmw's memory policy", path, exc)
        return None
    env[PROFILE_FILE] = str(path)
    env[QOS_FROM_XML] = "1"
    env[OURS] = str(path)
    _written = path
    return path


def profiles_xml(topics: Iterable[str], publication_mode: str = "SYNCHRONOUS") -> str:
    mode = PUBLISH_MODES.get(publication_mode.upper(), "SYNCHRONOUS")
    publish = f"<publishMode><kind>{mode}</kind></publishMode>" if mode else ""
    no_sharing = "<data_sharing><kind>OFF</kind></data_sharing>"
    lines = [
        '<?xml version="1.0" encoding="UTF-8" ?>',
        "<!-- Written by rover_web at each start (rover_web/ros/dds_profiles.py): edits are lost. -->",
        '<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">',
        "  <profiles>",
        "    <!-- What rmw_fastrtps sets when RMW_FASTRTPS_USE_QOS_FROM_XML is not 1, for every other endpoint. -->",
        '    <data_writer profile_name="rover_web_writer" is_default_profile="true">',
        f"      <qos>{publish}{no_sharing}</qos>",
        "      <historyMemoryPolicy>PREALLOCATED_WITH_REALLOC</historyMemoryPolicy>",
        "    </data_writer>",
        '    <data_reader profile_name="rover_web_reader" is_default_profile="true">',
        f"      <qos>{no_sharing}</qos>",
        "      <historyMemoryPolicy>PREALLOCATED_WITH_REALLOC</historyMemoryPolicy>",
        "    </data_reader>",
        "    <!-- The overlay readers: a sample's memory is freed once taken (overlays/bounds.py). -->",
    ]
    for topic in topics:
        lines += [f"    <data_reader profile_name={quoteattr(topic)}>",
                  f"      <qos>{no_sharing}</qos>",
                  "      <historyMemoryPolicy>DYNAMIC</historyMemoryPolicy>",
                  "    </data_reader>"]
    lines += ["  </profiles>", "</dds>", ""]
    return "\n".join(lines)
