"""ROVER_WEB_ROBOTS: parsing, the short form, name resolution, and each robot's settings."""

import pytest

from rover_web import config
from rover_web.core.robots import (
    DEFAULT_NAME,
    NAME_LISTS,
    Robot,
    RobotsError,
    from_text,
    kind_from_name,
    parse,
    settings_for,
)


def test_empty_is_the_one_robot_of_old_without_a_namespace():
    assert parse([]) == [Robot(DEFAULT_NAME)]
    assert parse([])[0].namespace == ""


def test_defaults_namespace_kind_and_title_come_from_the_name():
    boat, drone, other = parse([{"name": "boat2"}, "drone_a", {"name": "mule", "title": "Mule"}])
    assert (boat.name, boat.namespace, boat.kind, boat.label) == ("boat2", "/boat2", "boat", "boat2")
    assert (drone.name, drone.namespace, drone.kind) == ("drone_a", "/drone_a", "drone")
    assert (other.kind, other.label) == ("rover", "Mule")
    assert other.as_dict() == {"name": "mule", "namespace": "/mule", "kind": "rover", "title": "Mule"}


def test_explicit_fields_win():
    (robot,) = parse([{"name": "boat", "namespace": "/fleet/hull_1", "kind": "rover"}])
    assert (robot.namespace, robot.kind) == ("/fleet/hull_1", "rover")
    (bare,) = parse([{"name": "boat", "namespace": ""}])
    assert bare.namespace == ""


@pytest.mark.parametrize("value, message", [
    ({"name": "boat"}, "expected a list"),
    ("boat", "expected a list"),
    ([5], "expected an object"),
    ([{"name": "boat", "colour": "red"}], "unknown field(s) colour"),
    ([{}], "name None"),
    ([{"name": "Boat"}], "name 'Boat'"),
    ([{"name": "b" * 33}], "1-32"),
    ([{"name": "boat\n"}], "name"),  # \Z, not $: a trailing newline is not a name
    ([{"name": "boat", "namespace": "boat"}], "namespace 'boat'"),
    ([{"name": "boat", "namespace": "/boat/"}], "namespace"),
    ([{"name": "boat", "namespace": "/boat\n"}], "namespace"),
    ([{"name": "boat", "namespace": 7}], "namespace"),
    ([{"name": "boat", "kind": "tank"}], "kind 'tank'"),
    ([{"name": "boat", "title": "x" * 65}], "title"),
    ([{"name": "boat"}, {"name": "boat", "namespace": "/other"}], "two robots have the name 'boat'"),
    ([{"name": "a", "namespace": "/x"}, {"name": "b", "namespace": "/x"}], "two robots have the namespace '/x'"),
])
def test_malformed_entries_say_which_and_why(value, message):
    with pytest.raises(RobotsError) as raised:
        parse(value)
    assert message in str(raised.value)


def test_the_short_form_and_json_from_the_environment():
    assert from_text(" boat, drone ,, ") == [{"name": "boat"}, {"name": "drone"}]
    assert from_text("") == []
    assert from_text(' [{"name": "boat"}]') == '[{"name": "boat"}]'  # left to the JSON reader


@pytest.mark.parametrize("name, kind", [("boat", "boat"), ("boat_2", "boat"), ("drone7", "drone"),
                                        ("rover", "rover"), ("robot", "robot"), ("mule", "rover")])
def test_kind_from_name(name, kind):
    assert kind_from_name(name) == kind


def test_resolve_puts_configured_names_under_the_namespace():
    boat = Robot("boat", "/boat")
    assert boat.resolve("/cmd_vel") == "/boat/cmd_vel"
    assert boat.resolve("cmd_vel") == "/boat/cmd_vel"
    assert boat.resolve("/camera/image_raw") == "/boat/camera/image_raw"
    assert boat.resolve("~/private") == "~/private"
    assert Robot("robot").resolve("/cmd_vel") == "/cmd_vel"


def test_settings_for_resolves_every_topic_and_name_list():
    settings = config.load({}, environ={})
    boat = Robot("boat", "/boat")
    mine = settings_for(boat, settings, config.TOPIC_KEYS)
    assert mine is not settings
    assert mine["ROVER_WEB_CMD_VEL_TOPIC"] == "/boat/cmd_vel"
    assert mine["ROVER_WEB_ESTOP_TOPIC"] == "/boat/e_stop"
    assert mine["ROVER_WEB_WAYPOINTS_TOPIC"] == "/boat/waypoints"
    assert mine["ROVER_WEB_GOAL_TOPIC"] == "/boat/goal_pose"
    assert mine["ROVER_WEB_LINK_TOPICS"] == ["/boat/odom"]
    actions = settings["ROVER_WEB_ESTOP_CANCEL_ACTIONS"]
    assert actions and mine["ROVER_WEB_ESTOP_CANCEL_ACTIONS"] == ["/boat" + a for a in actions]
    for setting in config.SETTINGS:  # every topic setting, not only the ones named above
        key = config.PREFIX + setting.name
        if setting.kind in ("topic", "optional_topic") and settings[key]:
            assert mine[key] == boat.resolve(settings[key]), key
        elif key in NAME_LISTS:  # lists of names, each resolved
            assert mine[key] == [boat.resolve(name) for name in settings[key]], key
        else:
            assert mine[key] == settings[key], key
    assert settings["ROVER_WEB_CMD_VEL_TOPIC"] == "/cmd_vel"  # the shared settings are left alone


def test_settings_for_the_one_robot_of_old_are_the_settings():
    settings = config.load({}, environ={})
    assert settings_for(Robot("robot"), settings, config.TOPIC_KEYS) is settings
    # A first robot with a namespace resolves like any other.
    boat = settings_for(Robot("boat", "/boat"), settings, config.TOPIC_KEYS)
    assert boat["ROVER_WEB_CMD_VEL_TOPIC"] == "/boat/cmd_vel"


def test_config_keeps_the_parsed_robots_and_names_the_setting_when_wrong():
    loaded = config.load({}, environ={"ROVER_WEB_ROBOTS": "boat,drone"})
    assert loaded["ROVER_WEB_ROBOTS"] == [{"name": "boat", "namespace": "/boat", "kind": "boat", "title": "boat"},
                                          {"name": "drone", "namespace": "/drone", "kind": "drone", "title": "drone"}]
    assert config.load({}, environ={})["ROVER_WEB_ROBOTS"] == []
    with pytest.raises(config.ConfigError, match=r"ROVER_WEB_ROBOTS: two robots have the name 'boat'"):
        config.load({}, environ={"ROVER_WEB_ROBOTS": "boat,boat"})
    with pytest.raises(config.ConfigError, match="ROVER_WEB_ROBOTS"):
        config.load({"ROVER_WEB_ROBOTS": [{"name": "boat", "namespace": "/b a"}]}, environ={})
