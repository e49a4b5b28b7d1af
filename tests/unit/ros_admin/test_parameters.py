"""Parameter values checked against the node's descriptor before anything is sent."""

import math

import pytest

from rover_web.ros_admin.goals import Goal, GoalBook
from rover_web.ros_admin.names import goal_id, node_name
from rover_web.ros_admin.parameters import ParameterRefused, check_value


def param(kind, **extra):
    return {"name": "p", "type": kind, "read_only": False, "dynamic_typing": False, "range": None, **extra}


@pytest.mark.parametrize("kind,value,sent", [
    ("bool", False, False), ("integer", -5, -5), ("integer", 4.0, 4), ("double", 2, 2.0), ("string", "x", "x"),
    ("integer_array", [1, 2], [1, 2]), ("double_array", [1, 2.5], [1.0, 2.5]), ("string_array", [], []),
    ("bool_array", [True], [True]), ("byte_array", [0, 255], [0, 255]),
])
def test_values_of_each_type(kind, value, sent):
    assert check_value(param(kind), value) == (kind, sent)


@pytest.mark.parametrize("kind,value,code", [
    ("bool", 0, "bad_type"), ("integer", True, "bad_type"), ("integer", 1.5, "bad_type"),
    ("integer", 2**63, "out_of_range"), ("double", math.nan, "non_finite"), ("double", math.inf, "non_finite"),
    ("double", "1", "bad_type"), ("string", 1, "bad_type"), ("string", None, "bad_type"),
    ("integer_array", [1, None], "bad_type"), ("double_array", [math.nan], "non_finite"),
    ("byte_array", [256], "bad_type"), ("string_array", "ab", "bad_type"), ("not_set", None, "bad_type"),
])
def test_wrong_types_are_400(kind, value, code):
    with pytest.raises(ParameterRefused) as caught:
        check_value(param(kind), value)
    assert (caught.value.status, caught.value.code) == (400, code)


def test_read_only_is_409():
    with pytest.raises(ParameterRefused) as caught:
        check_value(param("string", read_only=True), "x")
    assert (caught.value.status, caught.value.code) == (409, "read_only")


@pytest.mark.parametrize("bounds,value,ok", [
    ({"kind": "integer", "from": 0, "to": 10, "step": 2}, 4, True),
    ({"kind": "integer", "from": 0, "to": 10, "step": 2}, 3, False),
    ({"kind": "integer", "from": 0, "to": 9, "step": 2}, 9, True),  # the upper bound is always allowed
    ({"kind": "integer", "from": 0, "to": 10, "step": 0}, 11, False),
    ({"kind": "double", "from": 0.0, "to": 1.0, "step": 0.0}, 1.0, True),
    ({"kind": "double", "from": 0.0, "to": 1.0, "step": 0.0}, 1.1, False),
    ({"kind": "double", "from": 0.0, "to": 1.0, "step": 0.1}, 0.3, True),
    ({"kind": "double", "from": 0.0, "to": 1.0, "step": 0.25}, 0.3, False),
])
def test_ranges(bounds, value, ok):
    kind = bounds["kind"]
    if ok:
        assert check_value(param(kind, range=bounds), value)[1] == value
    else:
        with pytest.raises(ParameterRefused) as caught:
            check_value(param(kind, range=bounds), value)
        assert caught.value.code == "out_of_range"


def test_dynamic_typing_takes_the_type_of_the_value():
    assert check_value(param("integer", dynamic_typing=True), "now text") == ("string", "now text")
    assert check_value(param("not_set"), [1, 2.5]) == ("double_array", [1.0, 2.5])


@pytest.mark.parametrize("path,name", [("talker", "/talker"), ("ns/sub/talker", "/ns/sub/talker"),
                                       ("9x", None), ("a b", None), ("a//b", None), ("a/", None),
                                       ("talker\n", None), ("", None), ("x" * 300, None)])
def test_node_names_in_urls(path, name):
    assert node_name(path) == name


def test_goal_ids():
    assert goal_id("0123456789abcdef" * 2) and not goal_id("0123456789ABCDEF" * 2)
    assert not goal_id("0" * 32 + "\n")


def test_goal_book_keeps_running_goals_and_the_newest_finished():
    book = GoalBook(keep_finished=2)
    goals = [Goal(f"{i:032x}", "/a", "t", None, "op") for i in range(5)]
    for g in goals:
        book.add(g)
    for g in goals[:4]:
        g.on_result("succeeded", {})
    book.add(Goal("f" * 32, "/a", "t", None, "op"))
    assert [g.goal_id for g in book.all()] == [goals[2].goal_id, goals[3].goal_id, goals[4].goal_id, "f" * 32]
    assert [g.goal_id for g in book.running()] == [goals[4].goal_id, "f" * 32]


def test_feedback_after_the_result_is_ignored():
    g = Goal("a" * 32, "/a", "t", None, "op")
    g.on_feedback({"n": 1})
    assert g.status == "executing"
    g.on_result("canceled", {})
    g.on_feedback({"n": 2})
    assert (g.status, g.feedback) == ("canceled", {"n": 1})
