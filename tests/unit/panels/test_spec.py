"""Panel files: the shipped drone panel, every std_msgs scalar, and each kind of mistake named."""

import copy
import math

import pytest

from rover_web.config import ConfigError
from rover_web.panels import scalars, spec
from rover_web.panels.msgs import field_kind


def valid() -> dict:
    return {"panels": {"rig": {
        "title": "Test rig",
        "light": {"display": "status", "idle": ["Idle"]},
        "displays": {
            "status": {"label": "Status", "topic": "/status", "type": "std_msgs/msg/String"},
            "speed": {"label": "Speed", "topic": "/speed", "type": "std_msgs/Float32"},
        },
        "controls": {
            "go": {"kind": "button", "label": "Go", "topic": "/phase", "type": "std_msgs/msg/Int8", "value": 1,
                   "enabled_when": {"status": ["Idle"]}, "confirm": True},
            "target": {"kind": "input", "label": "Target", "topic": "/target", "type": "std_msgs/msg/Int8",
                       "min": 0, "max": 100},
        },
    }}}


def parse(data):
    return spec.parse(data, "rig.toml", 2.0, field_kind)


def error_for(mutate) -> str:
    data = valid()
    mutate(data["panels"]["rig"], data)
    with pytest.raises(ConfigError) as err:
        parse(data)
    return str(err.value)


def test_the_shipped_drone_panel_reproduces_the_drone_gui():
    (drone,) = spec.load(None, 2.0, field_kind)
    assert drone.id == "drone"
    assert {(d.topic, d.type) for d in drone.displays} == {
        ("/status", "std_msgs/msg/String"), ("/id", "std_msgs/msg/Int8"),
        ("/location", "geometry_msgs/msg/Point"), ("/flight_height", "std_msgs/msg/Int8")}
    controls = {c.id: c for c in drone.controls}
    assert {(c.topic, c.value) for c in controls.values() if c.kind == "button"} == {
        ("/control_phase", 1), ("/control_phase", 2), ("/control_phase", 0)}
    assert all(c.type.name == "std_msgs/msg/Int8" for c in controls.values())
    assert controls["takeoff"].value == 1 and controls["takeoff"].enabled_when == (("status", ("Standby",)),)
    assert controls["return"].value == 2 and controls["return"].enabled_when == (("status", ("Hovering",)),)
    assert controls["stop"].value == 0 and controls["stop"].enabled_when == ()
    assert controls["destination"].topic == "/flight_destination"
    assert controls["destination"].enabled_when == (("status", ("Hovering",)),)
    assert controls["height"].topic == "/flight_height"
    assert all(c.requires_unlock for c in controls.values())
    assert drone.light == spec.LightSpec("status", ("Standby",), "Mission")


def test_a_valid_file_parses_with_defaults():
    (rig,) = parse(valid())
    assert rig.title == "Test rig" and rig.unlock_timeout_s == 60.0 and rig.stale_after_s == 2.0
    status = rig.display("status")
    assert status.field == "data" and status.kind == "string" and status.qos == "default"
    target = rig.control("target")
    assert (target.low, target.high, target.action) == (0, 100, "Send")
    assert rig.control("go").type.kind == "int"


@pytest.mark.parametrize("type_name, low, high", [
    ("std_msgs/msg/Int8", -128, 127), ("std_msgs/msg/UInt8", 0, 255), ("std_msgs/msg/Byte", 0, 255),
    ("std_msgs/msg/Char", 0, 255), ("std_msgs/msg/Int16", -32768, 32767), ("std_msgs/msg/UInt16", 0, 65535),
    ("std_msgs/msg/Int32", -2**31, 2**31 - 1), ("std_msgs/msg/UInt32", 0, 2**32 - 1),
    ("std_msgs/msg/Int64", -2**63, 2**63 - 1), ("std_msgs/msg/UInt64", 0, 2**64 - 1),
])
def test_integer_ranges_respect_the_type(type_name, low, high):
    stype = scalars.SCALAR_TYPES[type_name]
    assert scalars.coerce(stype, low) == low and scalars.coerce(stype, high) == high
    for outside in (low - 1, high + 1):
        with pytest.raises(scalars.InvalidValue) as err:
            scalars.coerce(stype, outside)
        assert err.value.code == "out_of_range" and f"from {low} to {high}" in str(err.value)
    assert scalars.coerce(stype, 3.0) == 3  # an integral JSON number is fine
    for wrong, code in ((2.5, "bad_type"), (True, "bad_type"), ("3", "bad_type"), (math.inf, "non_finite")):
        with pytest.raises(scalars.InvalidValue) as err:
            scalars.coerce(stype, wrong)
        assert err.value.code == code


def test_float_bool_and_string_values():
    f32, f64 = scalars.SCALAR_TYPES["std_msgs/msg/Float32"], scalars.SCALAR_TYPES["std_msgs/msg/Float64"]
    assert scalars.coerce(f32, 1) == 1.0 and isinstance(scalars.coerce(f32, 1), float)
    with pytest.raises(scalars.InvalidValue, match="out|from"):
        scalars.coerce(f32, 1e39)  # fits a double, not a float
    assert scalars.coerce(f64, 1e300) == 1e300
    for huge in (10 ** 400, -10 ** 400):  # valid JSON; float() of it would raise OverflowError
        with pytest.raises(scalars.InvalidValue) as err:
            scalars.coerce(f64, huge)
        assert err.value.code == "out_of_range" and "401 digits" in str(err.value)
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(scalars.InvalidValue) as err:
            scalars.coerce(f64, bad)
        assert err.value.code == "non_finite"
    boolean = scalars.SCALAR_TYPES["std_msgs/msg/Bool"]
    assert scalars.coerce(boolean, False) is False
    with pytest.raises(scalars.InvalidValue, match="true or false"):
        scalars.coerce(boolean, 1)
    string = scalars.SCALAR_TYPES["std_msgs/msg/String"]
    assert scalars.coerce(string, "hello") == "hello"
    with pytest.raises(scalars.InvalidValue) as err:
        scalars.coerce(string, "x" * 11, max_length=10)
    assert err.value.code == "too_long"
    with pytest.raises(scalars.InvalidValue, match="must be a string"):
        scalars.coerce(string, 5)


def _set(path, value):
    def mutate(panel, data):
        target = panel
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return mutate


def _drop(path):
    def mutate(panel, data):
        target = panel
        for key in path[:-1]:
            target = target[key]
        del target[path[-1]]
    return mutate


# Each mistake, and words its message must contain besides the file and panel.
MISTAKES = [
    ("unknown panel field", _set(["titel"], "x"), ["unknown field 'titel'"]),
    ("bad panel id", lambda p, d: d["panels"].update({"Bad Id": d["panels"].pop("rig")}), ["panel ids"]),
    ("panel not a table", lambda p, d: d["panels"].update({"rig": 5}), ["must be a table"]),
    ("non-positive unlock timeout", _set(["unlock_timeout_s"], 0), ["field 'unlock_timeout_s'", "positive"]),
    ("infinite stale time", _set(["stale_after_s"], math.inf), ["field 'stale_after_s'"]),
    ("missing label", _drop(["displays", "status", "label"]), ["display 'status'", "field 'label'", "required"]),
    ("missing topic", _drop(["controls", "go", "topic"]), ["control 'go'", "field 'topic'", "required"]),
    ("bad topic", _set(["controls", "go", "topic"], "control phase!"), ["field 'topic'", "ROS topic name"]),
    ("malformed type", _set(["displays", "status", "type"], "String"), ["field 'type'", "message type"]),
    ("uninstalled type", _set(["displays", "status", "type"], "nosuch_msgs/msg/Thing"),
     ["display 'status'", "field 'type'", "not installed"]),
    ("missing message field", _set(["displays", "status", "field"], "dat"),
     ["display 'status'", "field 'field'", "no field 'dat'"]),
    ("bad qos", _set(["displays", "status", "qos"], "fast"), ["field 'qos'", "sensor_data"]),
    ("bad digits", _set(["displays", "speed", "digits"], 12), ["field 'digits'"]),
    ("unknown display field", _set(["displays", "status", "colour"], "red"), ["display 'status'", "'colour'"]),
    ("unknown kind", _set(["controls", "go", "kind"], "slider"), ["control 'go'", "field 'kind'"]),
    ("control type not a scalar", _set(["controls", "go", "type"], "geometry_msgs/msg/Twist"),
     ["control 'go'", "field 'type'", "std_msgs scalar"]),
    ("button without value", _drop(["controls", "go", "value"]), ["control 'go'", "field 'value'", "needs the value"]),
    ("button value wrong type", _set(["controls", "go", "value"], "one"), ["field 'value'", "integer"]),
    ("button value out of range", _set(["controls", "go", "value"], 300),
     ["control 'go'", "field 'value'", "from -128 to 127", "300"]),
    ("button value non-finite", lambda p, d: p["controls"]["go"].update(type="std_msgs/msg/Float64", value=math.nan),
     ["field 'value'", "finite"]),
    ("value on an input", _set(["controls", "target", "value"], 3), ["control 'target'", "'value'", "input"]),
    ("min on a button", _set(["controls", "go", "min"], 0), ["control 'go'", "'min'", "button"]),
    ("input min outside the type", _set(["controls", "target", "min"], -200), ["field 'min'", "from -128 to 127"]),
    ("input max outside the type", _set(["controls", "target", "max"], 128), ["field 'max'", "from -128 to 127"]),
    ("input min above max", _set(["controls", "target", "min"], 101), ["field 'min'", "greater than max"]),
    ("range on a String input", lambda p, d: p["controls"]["target"].update(type="std_msgs/msg/String"),
     ["field 'min'", "no numeric range"]),
    ("enabled_when not a table", _set(["controls", "go", "enabled_when"], ["Idle"]), ["field 'enabled_when'"]),
    ("enabled_when unknown display", _set(["controls", "go", "enabled_when"], {"mode": ["Idle"]}),
     ["field 'enabled_when'", "display 'mode'"]),
    ("enabled_when empty list", _set(["controls", "go", "enabled_when"], {"status": []}),
     ["field 'enabled_when.status'", "non-empty list"]),
    ("enabled_when value of the wrong kind", _set(["controls", "go", "enabled_when"], {"status": [1]}),
     ["field 'enabled_when.status'", "can never match"]),
    ("confirm not a boolean", _set(["controls", "go", "confirm"], "yes"), ["field 'confirm'", "true or false"]),
    ("bad style", _set(["controls", "go", "style"], "blinking"), ["field 'style'"]),
    ("reserved control id", lambda p, d: p["controls"].update({"unlock": p["controls"].pop("go")}),
     ["control 'unlock'", "reserved"]),
    ("light on an unknown display", _set(["light", "display"], "mode"), ["light", "field 'display'", "'mode'"]),
    ("light without idle values", _drop(["light", "idle"]), ["light", "field 'idle'"]),
    ("one topic, two types", lambda p, d: p["controls"]["target"].update(topic="/phase", type="std_msgs/Int16"),
     ["control 'target'", "field 'type'", "/phase", "one topic carries one type"]),
    ("display and control disagree on a topic's type", _set(["controls", "target", "topic"], "/status"),
     ["field 'type'", "/status"]),
    ("empty panel", lambda p, d: (p.pop("controls"), p.pop("displays"), p.pop("light")),
     ["no displays and no controls"]),
    ("no panels", lambda p, d: d.update(panels={}), ["defines no panels"]),
    ("unknown top-level key", lambda p, d: d.update(panel={}), ["unknown field 'panel'"]),
]


@pytest.mark.parametrize("mutate, words", [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_each_mistake_names_the_file_panel_and_field(mutate, words):
    message = error_for(mutate)
    assert message.startswith("rig.toml: ")
    if "no panels" not in message and "'panel'" not in message and "Bad Id" not in message:
        assert "panel 'rig'" in message
    for word in words:
        assert word in message, message


def test_the_file_itself_is_checked(tmp_path):
    with pytest.raises(ConfigError, match=r"ROVER_WEB_PANELS_FILE: cannot read .*missing\.toml"):
        spec.load(tmp_path / "missing.toml", 2.0, field_kind)
    bad = tmp_path / "bad.toml"
    bad.write_text("[panels.rig\ntitle = 1")
    with pytest.raises(ConfigError, match=r"bad\.toml: not valid TOML"):
        spec.load(bad, 2.0, field_kind)


def test_a_file_on_disk_reports_its_path(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text('[panels.boat.controls.horn]\nkind = "button"\nlabel = "Horn"\ntopic = "/horn"\n'
                    'type = "std_msgs/msg/Bool"\nvalue = 1\n')
    with pytest.raises(ConfigError) as err:
        spec.load(path, 2.0, field_kind)
    assert str(err.value) == (f"{path}: panel 'boat', control 'horn', field 'value': "
                              "must be true or false for std_msgs/Bool, got 1")


def test_topics_are_made_absolute_and_nested_fields_are_read():
    data = valid()
    data["panels"]["rig"]["displays"]["lat"] = {"label": "Latitude", "topic": "fix",
                                                "type": "sensor_msgs/msg/NavSatFix", "field": "latitude"}
    data["panels"]["rig"]["displays"]["frame"] = {"label": "Frame", "topic": "fix",
                                                  "type": "sensor_msgs/NavSatFix", "field": "header.frame_id"}
    (rig,) = parse(data)
    assert rig.display("lat").topic == "/fix" and rig.display("lat").kind == "float"
    assert rig.display("frame").kind == "string"
    data["panels"]["rig"]["displays"]["frame"]["field"] = "header.nope"
    with pytest.raises(ConfigError, match="std_msgs/Header|no field 'nope'"):
        parse(copy.deepcopy(data))
