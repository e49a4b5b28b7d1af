"""Parameters whose names say they hold a secret: hidden below admin, never written to a log. Pure Python.

Robots keep credentials in parameters (an RTK caster's password, a cloud token, an API key). The
name is all there is to go on, so anything with pass, secret, token, key or cred in it counts,
whatever the case: hiding `keyframe_count` from a viewer costs little, showing `ntrip_password`
costs a lot.
"""

from __future__ import annotations

import re
from typing import Any

SECRET_NAME = re.compile(r"pass|secret|token|key|cred", re.IGNORECASE)
HIDDEN = "(hidden)"


def is_secret(name: str) -> bool:
    return bool(SECRET_NAME.search(name))


def hide_parameters(parameters: list[dict]) -> list[dict]:
    """The listing a role below admin sees: a secret's value is null and `hidden` true."""
    return [{**p, "value": None, "hidden": True} if is_secret(p["name"]) else {**p, "hidden": False}
            for p in parameters]


def scrub(value: Any, depth: int = 0) -> Any:
    """A copy of a JSON-like value for the operator log: values under secret-named keys replaced."""
    if depth > 32:
        return HIDDEN
    if isinstance(value, dict):
        return {k: HIDDEN if isinstance(k, str) and is_secret(k) else scrub(v, depth + 1) for k, v in value.items()}
    if isinstance(value, list):
        return [scrub(v, depth + 1) for v in value]
    return value
