"""The Scan the Code light sequence: RobotX GUI box behaviour plus code detection. Pure Python.

The light tower shows three colours, each for a while, then black, and repeats. A detector
(camera node) publishes the colour it sees, usually many times per light. The rules here:

- A colour repeated in consecutive messages is the same light still on, not a new box.
- Each new non-black colour fills the next of three boxes; black resets all three to black.
- Black after exactly three colours completes a code. A cycle with more than three colours, or
  with a colour outside the configured set ("unknown"), is an invalid cycle: it is reported and
  produces no code. Fewer than three colours before black is an incomplete cycle (the usual first
  cycle after start, joined mid-sequence, or a cycle cut by a spurious black): no code either.
- Confidence is how many complete cycles in a row produced the same code. Cycles that produce
  no code (invalid or incomplete) neither add to it nor reset it: they are not evidence of
  another code. A different code starts again at 1.
- A code is confirmed once its confidence reaches `confirm_cycles` (default 1); every further
  agreeing cycle confirms it again, so a consumer keeps hearing it while the buoy shows it.
- A stream gap longer than `stale_after_s` abandons the cycle in progress: whatever happened
  while nothing was heard (a missed black, a new code) must not be stitched into a code.

Unknown text (empty, long, markup) is counted and kept only as a short label; callers render it
as text. Nothing here raises on any input string.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

BLACK = "black"
UNKNOWN = "unknown"
CODE_LENGTH = 3
# Longest text worth matching against a colour name, and the longest label kept for the page.
MAX_TEXT_CHARS = 64
COLOUR_NAME_RE = re.compile(r"[a-z][a-z0-9_-]{0,31}\Z")

# Why a cycle produced no code.
UNKNOWN_COLOUR = "unknown_colour"
TOO_MANY_COLOURS = "too_many_colours"
TOO_FEW_COLOURS = "too_few_colours"
STREAM_GAP = "stream_gap"


def parse_colours(names: Iterable[str]) -> tuple[str, ...]:
    """The configured colour set, lower-cased; ValueError names what is wrong."""
    colours: list[str] = []
    for name in names:
        colour = name.strip().lower() if isinstance(name, str) else name
        if not isinstance(colour, str) or not COLOUR_NAME_RE.match(colour):
            raise ValueError(f"colour {name!r} is not a simple name such as red")
        if colour in (BLACK, UNKNOWN):
            raise ValueError(f"{colour!r} is reserved and cannot be a code colour")
        if colour in colours:
            raise ValueError(f"colour {colour!r} is listed twice")
        colours.append(colour)
    if len(colours) < 2:
        raise ValueError("name at least two colours: a code never shows one colour twice in a row")
    return tuple(colours)


@dataclass(frozen=True)
class Reading:
    """One message, classified: a configured colour, black or unknown (with a short label)."""

    colour: str
    text: str | None = None  # the received text, shortened, for unknown readings only


def classify(raw: Any, colours: tuple[str, ...]) -> Reading:
    if not isinstance(raw, str):
        return Reading(UNKNOWN, _label(repr(raw)))
    if len(raw) <= MAX_TEXT_CHARS:
        name = raw.strip().lower()
        if name == BLACK or name in colours:
            return Reading(name)
    return Reading(UNKNOWN, _label(raw))


def _label(text: str) -> str:
    return text if len(text) <= MAX_TEXT_CHARS else text[:MAX_TEXT_CHARS] + "…"


@dataclass
class Outcome:
    """What one message or clock check did: `changed` means the published state must be resent."""

    changed: bool = False
    cycle: dict | None = None       # the cycle that just ended, as kept in the history
    confirmed: dict | None = None   # the code to announce (publish on ROS, emit as an event)


class LightSequence:
    """State of the light tower as the operator sees it. Not thread-safe: the caller locks."""

    def __init__(self, colours: Iterable[str] = ("red", "green", "blue", "yellow"), *,
                 history_length: int = 10, confirm_cycles: int = 1, stale_after_s: float = 3.0):
        self.colours = parse_colours(colours)
        self.confirm_cycles = max(1, int(confirm_cycles))
        self.stale_after_s = float(stale_after_s)
        self.history: deque[dict] = deque(maxlen=history_length)
        self.light: str | None = None          # None until the first message
        self.light_text: str | None = None
        self.code: dict | None = None          # the last complete code
        self.counts = {"unknown_messages": 0, "codes": 0, "invalid_cycles": 0, "incomplete_cycles": 0}
        self.revision = 0
        self.last_message_mono: float | None = None
        self.last_message_at: float | None = None
        self._fresh = False
        self._cycle: list[str] = []            # colours since the last black, at most CODE_LENGTH + 1 kept
        self._cycle_length = 0
        self._cycle_problems: list[str] = []

    # --- input ---

    def observe(self, raw: Any, now_mono: float, now_wall: float) -> Outcome:
        """One message from the detector, at monotonic time now_mono (wall clock now_wall)."""
        reading = classify(raw, self.colours)
        outcome = Outcome(changed=not self._fresh)
        gap = self.last_message_mono is not None and now_mono - self.last_message_mono > self.stale_after_s
        self.last_message_mono, self.last_message_at = now_mono, round(now_wall, 3)
        self._fresh = True
        if gap and self._cycle_length:
            outcome.cycle = self._end_cycle(now_wall, forced=STREAM_GAP)
            self.light = None  # whatever shows now is a new light, even if it has the old colour
            outcome.changed = True
        if reading.colour == UNKNOWN:
            self.counts["unknown_messages"] += 1
            outcome.changed = True
        if reading.colour == self.light:  # the same light still on
            if reading.text != self.light_text:
                self.light_text = reading.text
                outcome.changed = True
            return self._finish(outcome)
        self.light, self.light_text = reading.colour, reading.text
        outcome.changed = True
        if reading.colour == BLACK:
            if self._cycle_length:
                outcome.cycle = self._end_cycle(now_wall)
                if outcome.cycle["result"] == "code":
                    outcome.confirmed = self._count_code(outcome.cycle["colours"], now_wall)
        else:
            self._add_colour(reading.colour)
        return self._finish(outcome)

    def check_fresh(self, now_mono: float) -> Outcome:
        """Call periodically: the state changes when the stream goes stale."""
        fresh = self.is_fresh(now_mono)
        if fresh == self._fresh:
            return Outcome()
        self._fresh = fresh
        return self._finish(Outcome(changed=True))

    def is_fresh(self, now_mono: float) -> bool:
        return self.last_message_mono is not None and now_mono - self.last_message_mono <= self.stale_after_s

    # --- the cycle ---

    def _add_colour(self, colour: str) -> None:
        self._cycle_length += 1
        if len(self._cycle) <= CODE_LENGTH:  # the fourth shows what broke the rule; more is noise
            self._cycle.append(colour)
        if colour == UNKNOWN and UNKNOWN_COLOUR not in self._cycle_problems:
            self._cycle_problems.append(UNKNOWN_COLOUR)
        if self._cycle_length == CODE_LENGTH + 1:
            self._cycle_problems.append(TOO_MANY_COLOURS)

    def _end_cycle(self, now_wall: float, forced: str | None = None) -> dict:
        problems = list(self._cycle_problems)
        if forced:
            result, problems = "incomplete", [forced] + problems
        elif problems:
            result = "invalid"
        elif self._cycle_length < CODE_LENGTH:
            result, problems = "incomplete", [TOO_FEW_COLOURS]
        else:
            result = "code"
        record = {"at": round(now_wall, 3), "result": result, "colours": list(self._cycle),
                  "length": self._cycle_length, "problems": problems}
        if result == "invalid":
            self.counts["invalid_cycles"] += 1
        elif result == "incomplete":
            self.counts["incomplete_cycles"] += 1
        self.history.appendleft(record)
        self._cycle, self._cycle_length, self._cycle_problems = [], 0, []
        return record

    def _count_code(self, colours: list[str], now_wall: float) -> dict | None:
        at = round(now_wall, 3)
        if self.code is not None and self.code["colours"] == colours:
            self.code["confidence"] += 1
            self.code["seen_at"] = at
        else:
            self.code = {"colours": list(colours), "text": ",".join(colours), "confidence": 1,
                         "first_seen_at": at, "seen_at": at, "confirmed": False}
        self.counts["codes"] += 1
        if self.code["confidence"] >= self.confirm_cycles:
            self.code["confirmed"] = True
            return dict(self.code, colours=list(colours))
        return None

    def _finish(self, outcome: Outcome) -> Outcome:
        if outcome.changed:
            self.revision += 1
        return outcome

    # --- output ---

    @property
    def boxes(self) -> list[str]:
        """The three boxes of the RobotX GUI: the cycle's first three colours, black when empty."""
        return (self._cycle[:CODE_LENGTH] + [BLACK] * CODE_LENGTH)[:CODE_LENGTH]

    def snapshot(self, now_mono: float) -> dict:
        """The JSON-ready state for GET /api/light_sequence and the `light_sequence` channel."""
        return {
            "revision": self.revision,
            "boxes": self.boxes,
            "light": self.light,
            "light_text": self.light_text,
            "cycle": {"colours": list(self._cycle), "length": self._cycle_length,
                      "problems": list(self._cycle_problems)},
            "code": None if self.code is None else dict(self.code, colours=list(self.code["colours"])),
            "history": [dict(h, colours=list(h["colours"]), problems=list(h["problems"])) for h in self.history],
            "counts": dict(self.counts),
            "fresh": self.is_fresh(now_mono),
            "last_message_at": self.last_message_at,
            "stale_after_s": self.stale_after_s,
            "confirm_cycles": self.confirm_cycles,
            "colours": list(self.colours),
        }
