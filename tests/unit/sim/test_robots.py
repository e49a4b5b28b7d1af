"""`--robots`: which robots, of which kind, in which namespace, running which parts where."""

import pytest

from rover_web.sim.__main__ import main
from rover_web.sim.robots import SPACING_EAST_M, Placement, Robot, parse_robots, plan


def test_kind_comes_from_the_name_or_after_a_colon():
    robots = parse_robots("boat,rover2,drone_a,alpha:drone,scout,boat_b:rover")
    assert robots == [Robot("boat", "boat"), Robot("rover2", "rover"), Robot("drone_a", "drone"),
                      Robot("alpha", "drone"), Robot("scout", "rover"), Robot("boat_b", "rover")]
    assert [r.namespace for r in robots[:2]] == ["/boat", "/rover2"]
    assert parse_robots("boat, drone") == [Robot("boat", "boat"), Robot("drone", "drone")]  # as people type lists


def test_each_kind_runs_its_parts():
    assert Robot("b", "boat").parts == ("rover", "light_buoy")
    assert Robot("r", "rover").parts == ("rover", "camera")
    assert Robot("d", "drone").parts == ("drone", "camera")


@pytest.mark.parametrize("text, reason", [
    ("Boat", "lower-case"), ("2boat", "lower-case"), ("boat-1", "lower-case"), ("", "lower-case"),
    ("boat,", "lower-case"), ("bo at", "lower-case"), ("boat\n", "lower-case"), ("/boat", "lower-case"),
    ("a:tank", "unknown kind"), ("a:", "unknown kind"), ("a:Drone", "unknown kind"),
    ("boat,boat", "named twice"), ("x:drone,x:boat", "named twice"),
])
def test_bad_lists_are_refused(text, reason):
    with pytest.raises(ValueError, match=reason):
        parse_robots(text)


def test_the_command_line_refuses_them_with_a_usage_error(capsys):
    for bad in ("boat,Boat", "boat,boat", "a:tank"):
        with pytest.raises(SystemExit) as exit_:
            main(["--robots", bad])
        assert exit_.value.code == 2
        assert "argument --robots" in capsys.readouterr().err


def test_driving_robots_start_apart_and_only_filters_parts_within_each_robot():
    robots = parse_robots("boat,drone,rover,rover2")
    assert plan(robots) == [
        Placement("rover", "/boat", 0.0), Placement("light_buoy", "/boat", 0.0),
        Placement("drone", "/drone", 0.0), Placement("camera", "/drone", 0.0),
        Placement("rover", "/rover", SPACING_EAST_M), Placement("camera", "/rover", 0.0),
        Placement("rover", "/rover2", 2 * SPACING_EAST_M), Placement("camera", "/rover2", 0.0),
    ]
    assert SPACING_EAST_M >= 10  # apart on a GPS map, not overlapping icons
    assert plan(robots, only=["camera"]) == [Placement("camera", ns, 0.0) for ns in ("/drone", "/rover", "/rover2")]
    assert plan(parse_robots("boat"), only=["drone"]) == []


def test_only_that_leaves_nothing_to_run_is_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--robots", "boat", "--only", "camera"])
    assert exit_.value.code == 2
    assert "leaves none of these robots anything to run" in capsys.readouterr().err


def test_each_placement_knows_its_robots_kind():
    assert [(p.namespace, p.kind) for p in plan(parse_robots("boat,alpha:boat,rover2"), only=["rover"])] == [
        ("/boat", "boat"), ("/alpha", "boat"), ("/rover2", "rover")]
