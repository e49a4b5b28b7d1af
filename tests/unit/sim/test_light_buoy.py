"""The simulated light buoy's rules and timing, without ROS."""

import argparse
import random

import pytest

from rover_web.sim.light_buoy import BuoyClock, add_arguments, random_code

COLOURS = ("red", "green", "blue", "yellow")


def test_codes_are_three_configured_colours_never_twice_in_a_row():
    rng = random.Random(1)
    seen = set()
    for _ in range(2000):
        code = random_code(rng, COLOURS)
        assert len(code) == 3 and set(code) <= set(COLOURS)
        assert code[0] != code[1] and code[1] != code[2]
        seen.add(code)
    assert len(seen) == 4 * 3 * 3  # every allowed code turns up, including a colour coming back (red, green, red)


def test_a_new_code_differs_from_the_old_one():
    rng = random.Random(2)
    for _ in range(500):
        old = random_code(rng, ("red", "green"))
        assert random_code(rng, ("red", "green"), avoid=old) != old


def test_the_same_seed_gives_the_same_codes():
    assert [random_code(random.Random(7), COLOURS) for _ in range(3)] == \
           [random_code(random.Random(7), COLOURS) for _ in range(3)]


def test_each_colour_shows_for_a_period_then_black_then_it_repeats():
    clock = BuoyClock(("red", "green", "blue"), period_s=1.0, black_s=1.0, start=100.0)
    timeline = [(100.0, "red"), (100.99, "red"), (101.0, "green"), (102.5, "blue"), (103.0, "black"),
                (103.99, "black")]
    for t, colour in timeline:
        assert clock.advance(t) == 0
        assert clock.light(t) == colour, t
    assert clock.advance(104.0) == 1 and clock.light(104.0) == "red"
    assert clock.advance(113.5) == 2 and clock.light(113.5) == "green" and clock.cycles == 3


def test_black_can_last_longer_than_a_colour():
    clock = BuoyClock(("red", "green", "blue"), period_s=0.2, black_s=1.0, start=0.0)
    assert clock.light(0.61) == "black" and clock.light(1.59) == "black"
    clock.advance(1.61)
    assert clock.light(1.61) == "red"


def test_a_new_code_starts_with_black_so_no_cycle_mixes_two_codes():
    clock = BuoyClock(("red", "green", "blue"), period_s=1.0, black_s=1.0, start=0.0)
    clock.restart_at_black(("yellow", "red", "green"), now=1.5)  # asked for while green was on
    assert clock.light(1.5) == "black" and clock.light(2.49) == "black"
    clock.advance(2.5)
    assert [clock.light(t) for t in (2.5, 3.5, 4.5, 5.5)] == ["yellow", "red", "green", "black"]


@pytest.mark.parametrize("argv", [["--buoy-drop", "1"], ["--buoy-drop", "-0.1"], ["--buoy-noise", "nan"],
                                  ["--buoy-period", "0"], ["--buoy-rate", "-5"], ["--buoy-colours", "red"],
                                  ["--buoy-colours", "red,black"]])
def test_bad_options_are_refused(argv, capsys):
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    with pytest.raises(SystemExit):
        parser.parse_args(argv)
