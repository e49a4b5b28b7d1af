"""The light sequence state machine (RobotX GUI boxes, code detection) and its hub glue."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.events.hub import EventHub, encode
from rover_web.scan_the_code.light_sequence import (
    BLACK,
    MAX_TEXT_CHARS,
    UNKNOWN,
    LightSequence,
    classify,
    parse_colours,
)
from rover_web.scan_the_code.service import CODE_CHANNEL, STATE_CHANNEL, ScanTheCodeService

COLOURS = ("red", "green", "blue", "yellow")


class Feed:
    """Drives a LightSequence with a clock that advances 0.1 s per message (a 10 Hz detector)."""

    def __init__(self, **kwargs):
        self.seq = LightSequence(COLOURS, **kwargs)
        self.t = 100.0
        self.outcomes = []

    def __call__(self, *texts, dt=0.1):
        for text in texts:
            self.t += dt
            self.outcomes.append(self.seq.observe(text, self.t, 1_700_000_000.0 + self.t))
        return self.outcomes[-1]

    def light(self, colour, repeats=10):
        """One light held on for `repeats` messages, as a camera detector reports it; returns
        the outcome of its first message (the one that changes something)."""
        first = self(colour)
        if repeats > 1:
            self(*[colour] * (repeats - 1))
        return first

    def cycle(self, *colours, repeats=10):
        for colour in colours:
            self.light(colour, repeats)
        return self.light(BLACK, repeats)

    @property
    def confirmed(self):
        return [o.confirmed["text"] for o in self.outcomes if o.confirmed]


# --- the RobotX GUI behaviour: fill and reset ---

def test_starts_with_three_black_boxes_and_no_light():
    seq = LightSequence(COLOURS)
    state = seq.snapshot(0.0)
    assert state["boxes"] == [BLACK, BLACK, BLACK]
    assert state["light"] is None and state["code"] is None and state["fresh"] is False


def test_each_new_colour_fills_the_next_box_and_black_resets_all():
    feed = Feed()
    feed("red")
    assert feed.seq.boxes == ["red", BLACK, BLACK]
    feed("green")
    assert feed.seq.boxes == ["red", "green", BLACK]
    feed("blue")
    assert feed.seq.boxes == ["red", "green", "blue"]
    assert feed.seq.light == "blue"
    feed(BLACK)
    assert feed.seq.boxes == [BLACK, BLACK, BLACK]
    assert feed.seq.light == BLACK
    feed("yellow")
    assert feed.seq.boxes == ["yellow", BLACK, BLACK]


def test_black_resets_even_an_unfinished_sequence():
    feed = Feed()
    feed("red", "green", BLACK)
    assert feed.seq.boxes == [BLACK, BLACK, BLACK]


def test_a_repeated_colour_is_the_same_light_not_a_new_box():
    feed = Feed()
    feed.light("red", 25)
    assert feed.seq.boxes == ["red", BLACK, BLACK]
    feed.light("green", 25)
    feed.light("green", 5)
    assert feed.seq.boxes == ["red", "green", BLACK]
    feed.light(BLACK, 30)
    assert feed.seq.boxes == [BLACK] * 3 and feed.seq.counts["incomplete_cycles"] == 1


def test_the_same_colour_again_after_another_is_a_new_box():
    feed = Feed()
    feed.cycle("red", "green", "red")
    assert feed.seq.code["colours"] == ["red", "green", "red"]


def test_colours_are_case_insensitive_and_trimmed():
    feed = Feed()
    feed("RED", " Red ", "gReEn\n", "Blue", "BLACK")
    assert feed.seq.code["colours"] == ["red", "green", "blue"]
    assert feed.seq.counts["unknown_messages"] == 0


def test_the_colour_set_is_configurable():
    seq = LightSequence(["White", "orange"])
    for i, text in enumerate(["white", "orange", "white", "black", "red"]):
        seq.observe(text, float(i), float(i))
    assert seq.code["colours"] == ["white", "orange", "white"]
    assert seq.light == UNKNOWN and seq.counts["unknown_messages"] == 1  # red is not in this set


@pytest.mark.parametrize("names, problem", [
    (["red"], "at least two"), (["red", "Red"], "twice"), (["red", "black"], "reserved"),
    (["red", "unknown"], "reserved"), (["red", "<b>"], "simple name"), (["red", ""], "simple name"),
])
def test_bad_colour_sets_are_refused(names, problem):
    with pytest.raises(ValueError, match=problem):
        parse_colours(names)


# --- detection ---

def test_three_colours_then_black_is_a_complete_code():
    feed = Feed()
    outcome = feed.cycle("red", "green", "blue")
    assert outcome.cycle["result"] == "code" and outcome.cycle["colours"] == ["red", "green", "blue"]
    assert outcome.confirmed["text"] == "red,green,blue"
    code = feed.seq.code
    assert code["colours"] == ["red", "green", "blue"] and code["confidence"] == 1 and code["confirmed"]
    # seen when the light went black: the first of the ten black messages
    assert code["seen_at"] == pytest.approx(1_700_000_000.0 + feed.t - 0.9, abs=0.01)
    assert feed.seq.history[0]["result"] == "code"


def test_no_code_before_black():
    feed = Feed()
    feed.light("red"), feed.light("green"), feed.light("blue")
    assert feed.seq.code is None and feed.confirmed == []


def test_joining_mid_sequence_gives_an_incomplete_cycle_then_the_code():
    feed = Feed()
    feed.light("green", 4)  # the app started while green was already on
    feed.light("blue")
    outcome = feed.light(BLACK)
    assert outcome.cycle["result"] == "incomplete" and outcome.cycle["problems"] == ["too_few_colours"]
    assert outcome.confirmed is None and feed.seq.code is None
    feed.cycle("red", "green", "blue")
    assert feed.confirmed == ["red,green,blue"]


def test_joining_during_the_first_colour_still_gives_the_code():
    feed = Feed()
    feed.light("red", 2)
    feed.light("green"), feed.light("blue")
    assert feed.light(BLACK).confirmed["text"] == "red,green,blue"


# --- rule violations: every one is an invalid (or incomplete) cycle and produces no code ---

def test_more_than_three_colours_before_black_is_invalid():
    feed = Feed()
    outcome = feed.cycle("red", "green", "blue", "yellow")
    assert outcome.cycle["result"] == "invalid" and outcome.cycle["problems"] == ["too_many_colours"]
    assert outcome.confirmed is None and feed.seq.code is None
    assert feed.seq.counts["invalid_cycles"] == 1
    assert outcome.cycle["colours"] == ["red", "green", "blue", "yellow"] and outcome.cycle["length"] == 4


def test_boxes_keep_the_first_three_and_the_cycle_says_it_is_invalid_before_black():
    feed = Feed()
    for colour in ("red", "green", "blue", "yellow"):
        feed.light(colour)
    state = feed.seq.snapshot(feed.t)
    assert state["boxes"] == ["red", "green", "blue"]
    assert state["cycle"]["problems"] == ["too_many_colours"]


def test_a_cycle_without_black_stays_bounded():
    feed = Feed()
    for _ in range(10_000):
        feed("red", "green")
    assert feed.seq.snapshot(feed.t)["cycle"]["colours"] == ["red", "green", "red", "green"]
    outcome = feed(BLACK)
    assert outcome.cycle["length"] == 20_000 and len(outcome.cycle["colours"]) == 4


def test_an_unknown_colour_makes_the_cycle_invalid():
    feed = Feed()
    outcome = feed.cycle("red", "purple", "blue")
    assert outcome.cycle["result"] == "invalid" and outcome.cycle["problems"] == ["unknown_colour"]
    assert outcome.cycle["colours"] == ["red", UNKNOWN, "blue"]
    assert feed.seq.code is None and feed.seq.counts["unknown_messages"] == 10


def test_a_single_noisy_unknown_reading_spoils_its_cycle_only():
    feed = Feed()
    feed.light("red", 5), feed("<noise>"), feed.light("red", 5)
    outcome = feed.cycle("green", "blue")
    assert outcome.cycle["result"] == "invalid"
    assert set(outcome.cycle["problems"]) == {"unknown_colour", "too_many_colours"}
    feed.cycle("red", "green", "blue")
    assert feed.confirmed == ["red,green,blue"]


def test_fewer_than_three_colours_is_incomplete_not_a_code():
    feed = Feed()
    outcome = feed.cycle("red", "green")
    assert outcome.cycle["result"] == "incomplete" and outcome.confirmed is None
    assert feed.seq.counts == {"unknown_messages": 0, "codes": 0, "invalid_cycles": 0, "incomplete_cycles": 1}


def test_a_spurious_black_splits_a_cycle_without_inventing_a_code():
    feed = Feed()
    feed.cycle("red", "green", "blue")
    feed.light("red"), feed("black"), feed.light("red", 9), feed.light("green"), feed.light("blue"), feed.light(BLACK)
    assert [h["result"] for h in feed.seq.history] == ["code", "incomplete", "code"]
    assert feed.confirmed == ["red,green,blue", "red,green,blue"]


def test_a_stream_gap_abandons_the_cycle_in_progress():
    feed = Feed(stale_after_s=3.0)
    feed.light("red"), feed.light("green")
    feed.t += 10.0  # nothing heard for 10 s: the buoy may have shown anything
    outcome = feed("green")
    assert outcome.cycle["result"] == "incomplete" and outcome.cycle["problems"] == ["stream_gap"]
    assert feed.seq.boxes == ["green", BLACK, BLACK]  # what shows now is a new light
    feed.light("blue"), feed.light(BLACK)
    assert feed.seq.code is None


# --- confidence and confirmation ---

def test_confidence_counts_consecutive_agreeing_cycles():
    feed = Feed()
    for expected in (1, 2, 3):
        feed.cycle("red", "green", "blue")
        assert feed.seq.code["confidence"] == expected
    first_seen = feed.seq.code["first_seen_at"]
    assert feed.seq.code["seen_at"] > first_seen


def test_a_different_code_starts_again_at_one():
    feed = Feed()
    feed.cycle("red", "green", "blue"), feed.cycle("red", "green", "blue")
    feed.cycle("blue", "green", "red")
    assert feed.seq.code["colours"] == ["blue", "green", "red"] and feed.seq.code["confidence"] == 1
    feed.cycle("red", "green", "blue")
    assert feed.seq.code["colours"] == ["red", "green", "blue"] and feed.seq.code["confidence"] == 1


def test_cycles_without_a_code_neither_add_nor_reset_confidence():
    feed = Feed()
    feed.cycle("red", "green", "blue")
    feed.cycle("red", "green", "blue", "yellow")  # invalid
    feed.cycle("green", "blue")                   # incomplete
    feed.cycle("red", "green", "blue")
    assert feed.seq.code["confidence"] == 2


def test_with_confirm_cycles_two_the_first_cycle_is_not_announced():
    feed = Feed(confirm_cycles=2)
    first = feed.cycle("red", "green", "blue")
    assert first.confirmed is None
    assert feed.seq.code["confidence"] == 1 and feed.seq.code["confirmed"] is False
    second = feed.cycle("red", "green", "blue")
    assert second.confirmed["text"] == "red,green,blue" and second.confirmed["confidence"] == 2
    assert feed.seq.code["confirmed"] is True
    feed.cycle("red", "green", "blue")  # every further agreeing cycle confirms it again
    assert feed.confirmed == ["red,green,blue", "red,green,blue"]
    feed.cycle("yellow", "red", "green")  # a new code must earn its confirmations again
    assert feed.seq.code["confirmed"] is False and feed.confirmed[-1] == "red,green,blue"


def test_history_is_short_and_newest_first():
    feed = Feed(history_length=3)
    for colours in (("red", "green", "blue"), ("green", "blue", "red"), ("red", "green"),
                    ("blue", "red", "green"), ("yellow", "red", "blue")):
        feed.cycle(*colours)
    assert [h["colours"] for h in feed.seq.history] == [["yellow", "red", "blue"], ["blue", "red", "green"],
                                                        ["red", "green"]]


# --- bad input ---

@pytest.mark.parametrize("text", ["", " ", "purple", "<img src=x onerror=alert(1)>", "x" * 100_000,
                                  "red\x00", "ređ", "\ud800", "r" * (MAX_TEXT_CHARS + 1)])
def test_bad_text_is_counted_and_shown_as_unknown(text):
    feed = Feed()
    feed("red", text)
    state = feed.seq.snapshot(feed.t)
    assert state["light"] == UNKNOWN and state["counts"]["unknown_messages"] == 1
    assert state["boxes"] == ["red", UNKNOWN, BLACK]
    assert len(state["light_text"]) <= MAX_TEXT_CHARS + 1
    assert state["light_text"] == (text if len(text) <= MAX_TEXT_CHARS else text[:MAX_TEXT_CHARS] + "…")
    json.loads(encode(state))  # still valid JSON for the browsers


def test_a_long_string_that_starts_with_a_colour_is_not_that_colour():
    assert classify("red" + " " * 200, COLOURS).colour == UNKNOWN


def test_non_string_input_is_unknown():
    assert classify(None, COLOURS).colour == UNKNOWN
    assert classify(b"red", COLOURS).colour == UNKNOWN


def test_repeated_unknown_readings_are_one_light_but_all_counted():
    feed = Feed()
    feed("red", "??", "!!", "??")
    assert feed.seq.boxes == ["red", UNKNOWN, BLACK]
    assert feed.seq.counts["unknown_messages"] == 3 and feed.seq.light_text == "??"


# --- what changes the published state ---

def test_only_visible_changes_bump_the_revision():
    feed = Feed()
    assert feed("red").changed
    revision = feed.seq.revision
    assert not any(feed("red").changed for _ in range(20))  # the same light still on
    assert feed.seq.revision == revision
    assert feed("green").changed and feed.seq.revision == revision + 1
    assert feed("zzz").changed and feed("zzz").changed  # every unknown message changes the counter


def test_freshness_goes_stale_after_silence_and_back_on_the_next_message():
    seq = LightSequence(COLOURS, stale_after_s=3.0)
    assert not seq.check_fresh(0.0).changed  # never heard: not fresh, nothing to announce
    seq.observe("red", 10.0, 10.0)
    assert seq.snapshot(12.9)["fresh"] is True
    assert not seq.check_fresh(12.9).changed
    assert seq.check_fresh(13.1).changed
    assert seq.snapshot(13.1)["fresh"] is False
    assert not seq.check_fresh(14.0).changed
    assert seq.observe("red", 14.0, 14.0).changed  # the same light, but fresh again
    assert seq.snapshot(14.0)["fresh"] is True


# --- properties ---

@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(st.sampled_from(list(COLOURS) + ["black", "BLACK", "Red"]), st.text(max_size=80)),
                max_size=200))
def test_any_input_keeps_the_invariants(texts):
    seq = LightSequence(COLOURS, history_length=5)
    for i, text in enumerate(texts):
        outcome = seq.observe(text, i * 0.1, i * 0.1)
        state = seq.snapshot(i * 0.1)
        assert len(state["boxes"]) == 3
        assert all(b in COLOURS or b in (BLACK, UNKNOWN) for b in state["boxes"])
        assert len(state["history"]) <= 5
        if outcome.confirmed:
            colours = outcome.confirmed["colours"]
            assert len(colours) == 3 and all(c in COLOURS for c in colours)
            assert colours[0] != colours[1] and colours[1] != colours[2]
        json.loads(encode(state))


codes = st.lists(st.sampled_from(COLOURS), min_size=3, max_size=3).filter(lambda c: c[0] != c[1] and c[1] != c[2])


@settings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(codes, st.lists(st.integers(1, 8), min_size=4, max_size=4)), min_size=1, max_size=6))
def test_clean_cycles_of_any_length_give_exactly_their_codes(cycles):
    feed = Feed()
    feed.light(BLACK, 1)
    for code, repeats in cycles:
        for colour, n in zip(code + [BLACK], repeats, strict=True):
            feed.light(colour, n)
    assert feed.confirmed == [",".join(code) for code, _ in cycles]
    last = cycles[-1][0]
    streak = 0
    for code, _ in reversed(cycles):
        if code != last:
            break
        streak += 1
    assert feed.seq.code["confidence"] == streak


# --- the feature glue: hub channels and the code publisher ---

class Clock:
    def __init__(self):
        self.t = 50.0

    def __call__(self):
        return self.t


def test_glue_publishes_state_on_change_and_announces_each_confirmed_code():
    hub, clock, published = EventHub(), Clock(), []
    feature = ScanTheCodeService(LightSequence(COLOURS), hub, published.append, clock=clock, wall_clock=clock)
    assert hub.latest(STATE_CHANNEL)["boxes"] == [BLACK] * 3
    with hub.subscribe([STATE_CHANNEL, CODE_CHANNEL]) as sub:
        sub.snapshot()
        for text in ["red"] * 5 + ["green"] * 5 + ["blue"] * 5 + ["black"] * 5:
            clock.t += 0.1
            feature.observe(text)
        frames = [block for block in sub.wait(0.1).decode().split("\n\n") if block]
    assert published == [["red", "green", "blue"]]
    events = [f.split("\n")[1] for f in frames]
    assert events == ["event: light_sequence", "event: scan_code"]  # conflated state, then the event
    code = json.loads(frames[1].split("\n")[2][len("data: "):])
    assert code["text"] == "red,green,blue" and code["confidence"] == 1
    state = hub.latest(STATE_CHANNEL)
    assert state["code"]["text"] == "red,green,blue" and state["revision"] == 4


def test_glue_survives_a_failing_code_publisher_and_reports_staleness():
    hub, clock = EventHub(), Clock()

    def broken(colours):
        raise RuntimeError("publisher destroyed")

    feature = ScanTheCodeService(LightSequence(COLOURS, stale_after_s=1.0), hub, broken, clock=clock, wall_clock=clock)
    for text in ("red", "green", "blue", "black"):
        clock.t += 0.1
        feature.observe(text)
    assert hub.latest(STATE_CHANNEL)["code"]["text"] == "red,green,blue"
    assert hub.latest(STATE_CHANNEL)["fresh"] is True
    clock.t += 1.5
    feature.check_fresh()
    assert hub.latest(STATE_CHANNEL)["fresh"] is False
