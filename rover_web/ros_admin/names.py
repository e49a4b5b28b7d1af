"""ROS node names as they appear in URLs, and goal ids. Pure Python."""

from __future__ import annotations

import re

_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
GOAL_ID = re.compile(r"[0-9a-f]{32}\Z")
MAX_NODE_NAME = 255


def node_name(path: str) -> str | None:
    """'ns/sub/talker' (the URL form, no leading '/') -> '/ns/sub/talker'; None if not a node name."""
    if not isinstance(path, str) or not path or len(path) > MAX_NODE_NAME:
        return None
    tokens = path.strip("/").split("/") if path.startswith("/") else path.split("/")
    if not all(_TOKEN.match(t) for t in tokens):
        return None
    return "/" + "/".join(tokens)


def goal_id(text: str) -> str | None:
    return text if isinstance(text, str) and GOAL_ID.match(text) else None
