"""Allow and deny rules, navigation goals and secret names (issue 27). Pure Python."""

import pytest

from rover_web.config import defaults
from rover_web.ros_admin.access import AccessRules, parameter_subjects, parse_rules
from rover_web.ros_admin.navigation import navigation_refusal
from rover_web.ros_admin.secret_params import HIDDEN, hide_parameters, is_secret, scrub

DEFAULT_DENY = defaults()["ROVER_WEB_ROS_ADMIN_DENY"]


def rules(allow=(), deny=DEFAULT_DENY):
    return AccessRules(parse_rules(list(allow), "ALLOW"), parse_rules(list(deny), "DENY"))


@pytest.mark.parametrize("subjects", [
    parameter_subjects("/base/driver", "use_sim_time"),
    [("service", "/base/driver/set_parameters")],
    [("service", "/base/driver/set_parameters_atomically")],
    [("service", "/nav/controller_server/change_state")],
    [("service", "/cam/load_parameters")],
    [("service", "/lifecycle_manager_navigation/manage_nodes")],
    [("service", "/navigate_to_pose/_action/send_goal")],  # a goal behind the goal checks' back
    [("service", "/ComponentManager/_container/load_node")],  # runs any plugin's code
])
def test_the_default_deny_list(subjects):
    code, message = rules().refusal(subjects)
    assert code == "denied" and "ROVER_WEB_ROS_ADMIN_DENY" in message


@pytest.mark.parametrize("subjects", [
    parameter_subjects("/base/driver", "max_speed"),
    [("service", "/base/driver/describe_parameters")],  # reading is fine
    [("service", "/camera/enable"), ("node", "/camera")],
    [("action", "/fibonacci")],
])
def test_what_the_default_deny_list_lets_through(subjects):
    assert rules().refusal(subjects) is None


def test_kinds_node_and_qualified_parameters():
    deny = rules(deny=["node:/base/*", "param:/arm/*/gain"])
    assert deny.refusal(parameter_subjects("/base/driver", "x"))[0] == "denied"
    assert deny.refusal([("service", "/enable"), ("node", "/base/driver")])[0] == "denied"
    assert deny.refusal(parameter_subjects("/arm/joint1", "gain"))[0] == "denied"
    assert deny.refusal(parameter_subjects("/arm/joint1", "speed")) is None
    assert deny.refusal([("service", "/base/enable")]) is None  # node: patterns are about nodes only


def test_a_pattern_without_a_kind_matches_any_kind_and_case_counts():
    deny = rules(deny=["*/arm*"])
    assert deny.refusal([("service", "/drone/arming")])[0] == "denied"
    assert deny.refusal([("action", "/drone/arm")])[0] == "denied"
    assert deny.refusal([("service", "/drone/Arming")]) is None


def test_an_allow_list_admits_only_what_it_names_and_deny_still_wins():
    allow = rules(allow=["service:/camera/*", "node:/tuning/*"])
    assert allow.refusal([("service", "/camera/enable")]) is None
    assert allow.refusal(parameter_subjects("/tuning/pid", "kp")) is None
    assert allow.refusal([("service", "/arm")])[0] == "not_allowed"
    assert allow.refusal(parameter_subjects("/base", "kp"))[0] == "not_allowed"
    assert allow.refusal(parameter_subjects("/tuning/pid", "use_sim_time"))[0] == "denied"


@pytest.mark.parametrize("entry", ["topic:/x", "service:", "param:"])
def test_bad_entries_name_the_setting(entry):
    with pytest.raises(ValueError, match=f"DENY: '{entry}'"):
        parse_rules([entry], "DENY")


@pytest.mark.parametrize("action,type_name,refused", [
    ("/navigate_to_pose", "test_msgs/action/Fibonacci", True),
    ("/robot1/navigate_through_poses", "x/action/Y", True),
    ("/follow_gps_waypoints", "x/action/Y", True),
    ("/backup", "x/action/Y", True),
    ("/go", "nav2_msgs/action/NavigateToPose", True),
    ("/go", "nav2_msgs/action/Spin", True),
    ("/plan", "nav2_msgs/action/ComputePathToPose", False),  # only plans
    ("/fibonacci", "test_msgs/action/Fibonacci", False),
    ("/navigate_to_pose_viewer", "x/action/Y", False),
    ("/x", None, False),
])
def test_navigation_goals(action, type_name, refused):
    reason = navigation_refusal(action, type_name)
    assert (reason is not None) == refused
    if refused:
        assert "/api/maps/<map>/goal" in reason and "/api/waypoints/send" in reason


@pytest.mark.parametrize("name,secret", [("ntrip_password", True), ("api_key", True), ("AWS_SECRET", True),
                                         ("cloud.token", True), ("credentials_file", True), ("passphrase", True),
                                         ("max_speed", False), ("frame_id", False)])
def test_secret_names(name, secret):
    assert is_secret(name) is secret


def test_hidden_values_and_scrubbed_logs():
    listed = hide_parameters([{"name": "password", "value": "x"}, {"name": "gain", "value": 1.0}])
    assert listed == [{"name": "password", "value": None, "hidden": True},
                      {"name": "gain", "value": 1.0, "hidden": False}]
    assert scrub({"user": "a", "password": "b", "inner": [{"Token": "c", "n": 1}]}) == {
        "user": "a", "password": HIDDEN, "inner": [{"Token": HIDDEN, "n": 1}]}


def test_a_configured_deny_list_names_the_defaults_it_leaves_out():
    from rover_web.ros_admin.access import dropped

    default = parse_rules(DEFAULT_DENY, "DENY")
    assert dropped(parse_rules(["node:/px4*"], "DENY"), default) == list(default)
    assert dropped(parse_rules([*DEFAULT_DENY, "node:/px4*"], "DENY"), default) == []
    # A `*` of the kind (or of every kind) keeps them; a narrower look-alike does not.
    assert dropped(parse_rules(["param:*", "service:*"], "DENY"), default) == []
    assert dropped(parse_rules(["*"], "DENY"), default) == []
    kept_but_one = [e for e in DEFAULT_DENY if e != "service:*/set_parameters*"] + ["service:*/set_parameters"]
    assert [str(r) for r in dropped(parse_rules(kept_but_one, "DENY"), default)] == ["service:*/set_parameters*"]
    assert [str(r) for r in dropped(parse_rules(["param:*", "node:*"], "DENY"), default)] == \
        [e for e in DEFAULT_DENY if e.startswith("service:")]
