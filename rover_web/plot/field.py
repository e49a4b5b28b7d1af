"""Field paths into a message (`twist.twist.linear.x`, `position[2]`) and reading a number at one. Pure Python."""

from __future__ import annotations

import math
import re

from rover_web.web.api_messages import explain

# \Z, not $: "$" also matches before a trailing newline.
_SEGMENT = r"[A-Za-z_][A-Za-z0-9_]*(?:\[\d{1,6}\])*"
PATH_RE = re.compile(rf"{_SEGMENT}(?:\.{_SEGMENT})*\Z")
_PART_RE = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")
MAX_PATH_CHARS = 200

Step = str | int


class FieldError(ValueError):
    """A field path that is malformed, missing from the type, or not a number; `code` says which."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


def parse_path(text: str) -> tuple[Step, ...]:
    """'pose.position[2]' -> ('pose', 'position', 2)."""
    if not text or len(text) > MAX_PATH_CHARS or not PATH_RE.match(text):
        raise FieldError(explain("field must be a path like twist.twist.linear.x or position[2], not %(text)s",
                                 text=repr(text[:40])),
                         "bad_field")
    return tuple(name if name else int(index) for name, index in _PART_RE.findall(text))


def read_number(msg, steps: tuple[Step, ...]) -> float | None:
    """The number at `steps` in a message, or None when this message has none there (a short array)."""
    value = msg
    try:
        for step in steps:
            value = value[step] if isinstance(step, int) else getattr(value, step)
    except (IndexError, AttributeError):
        return None
    if isinstance(value, (bytes, bytearray)):
        return float(value[0]) if value else None
    return float(value)


def finite(value: float | None) -> bool:
    return value is not None and math.isfinite(value)
