"""What a panel allows, shows and locks, with a fake clock."""

import pytest

from rover_web.panels import scalars, spec
from rover_web.panels.msgs import field_kind
from rover_web.panels.state import PanelState, format_value


class Clock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


@pytest.fixture
def drone():
    (panel,) = spec.load(None, 2.0, field_kind)
    clock = Clock()
    return PanelState(panel, clock), clock


def control(state, cid):
    return state.spec.control(cid)


def test_a_new_panel_is_locked_and_knows_nothing(drone):
    state, _clock = drone
    view = state.view()
    assert view["locked"] is True and view["light"] == "unknown"
    assert all(not c["enabled"] for c in view["controls"].values())
    assert view["controls"]["stop"]["reason"] == "the Drone panel is locked; unlock it first"
    assert view["displays"]["status"] == {"value": None, "text": "—", "fresh": False}
    state.unlock()
    assert state.refusal(control(state, "takeoff")).reason == (
        "Take off needs Status to be Standby; no Status has been received yet")
    assert state.refusal(control(state, "stop")) is None  # Stop has no rule: always allowed once unlocked


@pytest.mark.parametrize("status, enabled", [
    ("Standby", {"takeoff", "stop", "height"}),
    ("Flying", {"stop"}),
    ("Hovering", {"destination", "return", "stop", "height"}),
])
def test_buttons_follow_the_status(drone, status, enabled):
    state, _clock = drone
    state.unlock()
    state.update("status", status)
    view = state.view()
    assert {cid for cid, c in view["controls"].items() if c["enabled"]} == enabled
    assert view["light"] == ("green" if status == "Standby" else "red")
    if status == "Flying":
        assert view["controls"]["takeoff"]["reason"] == "Take off is only allowed when Status is Standby; it is Flying"
        assert view["controls"]["height"]["reason"].endswith("Status is Standby or Hovering; it is Flying")


def test_a_stale_status_allows_only_unconditional_controls(drone):
    state, clock = drone
    state.unlock()
    state.update("status", "Standby")
    clock.t += 2.5
    refusal = state.refusal(control(state, "takeoff"))
    assert refusal.code == "not_allowed"
    assert refusal.reason == "Take off needs Status to be Standby; the last Status (Standby) is 2.5 s old"
    assert state.refusal(control(state, "stop")) is None
    assert state.view()["light"] == "unknown"
    assert state.view()["displays"]["status"]["fresh"] is False


def test_unlock_times_out_after_inactivity_and_commands_renew_it(drone):
    state, clock = drone
    state.update("status", "Standby")
    state.unlock()
    clock.t += 59.0
    state.update("status", "Standby")
    assert not state.locked()
    state.renew()  # an accepted command at t+59
    clock.t += 59.0
    state.update("status", "Standby")
    assert not state.locked() and not state.expire()
    clock.t += 1.0
    assert state.locked()
    assert state.refusal(control(state, "takeoff")).code == "locked"
    assert state.expire() is True and state.expire() is False  # reported once
    state.renew()  # renewing a locked panel does not unlock it
    assert state.locked()


def test_relock_reports_whether_it_was_unlocked(drone):
    state, _clock = drone
    assert state.relock() is False
    state.unlock()
    assert state.relock() is True and state.locked()


def test_controls_that_need_no_unlock(drone):
    (panel,) = spec.parse({"panels": {"p": {"controls": {"horn": {
        "kind": "button", "label": "Horn", "topic": "/horn", "type": "std_msgs/Bool", "value": True,
        "requires_unlock": False}}}}}, "p.toml", 2.0, field_kind)
    state = PanelState(panel, Clock())
    assert state.locked() and state.refusal(panel.control("horn")) is None


def test_input_values_are_checked_against_the_control_range(drone):
    state, _clock = drone
    destination = control(state, "destination")
    assert state.value_for(destination, {"value": 7}) == 7
    for body, code in (({}, "missing_field"), ({"value": None}, "missing_field"), ({"value": 128}, "out_of_range"),
                       ({"value": -1}, "out_of_range"), ({"value": "7"}, "bad_type"), ({"value": 1.5}, "bad_type"),
                       ({"value": True}, "bad_type")):
        with pytest.raises(scalars.InvalidValue) as err:
            state.value_for(destination, body)
        assert err.value.code == code
    with pytest.raises(scalars.InvalidValue, match=r"'value' must be from 0 to 127 for std_msgs/Int8, got 128"):
        state.value_for(destination, {"value": 128})
    assert state.value_for(control(state, "takeoff"), {}) == 1  # a button publishes its own value


def test_rules_do_not_confuse_booleans_and_numbers():
    (panel,) = spec.parse({"panels": {"p": {
        "displays": {"armed": {"label": "Armed", "topic": "/armed", "type": "std_msgs/Bool"},
                     "mode": {"label": "Mode", "topic": "/mode", "type": "std_msgs/UInt8"}},
        "controls": {"go": {"kind": "button", "label": "Go", "topic": "/go", "type": "std_msgs/Bool", "value": True,
                            "enabled_when": {"armed": [True], "mode": [1]}, "requires_unlock": False}}}}},
        "p.toml", 2.0, field_kind)
    state = PanelState(panel, Clock())
    state.update("armed", 1)  # not a boolean: must not count as true
    state.update("mode", 1)
    assert state.refusal(panel.control("go")) is not None
    state.update("armed", True)
    assert state.refusal(panel.control("go")) is None
    state.update("mode", True)
    assert state.refusal(panel.control("go")) is not None


def test_values_are_formatted_for_people():
    (panel,) = spec.load(None, 2.0, field_kind)
    location, height, status = panel.display("location"), panel.display("flight_height"), panel.display("status")
    assert format_value(location, {"x": 1.0, "y": 2.25, "z": 5.0}) == "x 1.0 · y 2.2 · z 5.0 m"
    assert format_value(height, 5) == "5 m"
    assert format_value(status, "Standby") == "Standby"
    assert format_value(status, None) == "—"


def test_detail_lists_configuration_and_ages(drone):
    state, clock = drone
    state.update("status", "Standby")
    clock.t += 0.5
    detail = state.detail()
    status = detail["displays"][0]
    assert status["id"] == "status" and status["age_s"] == 0.5 and status["fresh"] is True
    takeoff = next(c for c in detail["controls"] if c["id"] == "takeoff")
    assert takeoff["value"] == 1 and takeoff["enabled_when"] == {"status": ["Standby"]} and takeoff["confirm"]
    destination = next(c for c in detail["controls"] if c["id"] == "destination")
    assert (destination["min"], destination["max"], destination["action"]) == (0, 127, "Start")
    assert detail["light"]["state"] == "green"



def test_the_e_stop_refuses_every_control_but_the_allowed_ones_and_the_page_says_so():
    (panel,) = spec.load(None, 2.0, field_kind)
    engaged = [False]
    state = PanelState(panel, Clock(), estop_engaged=lambda: engaged[0])
    state.unlock()
    assert state.refusal(control(state, "stop")) is None
    engaged[0] = True
    for cid in ("takeoff", "destination", "return", "height"):
        refusal = state.refusal(control(state, cid))
        assert refusal.code == "estop_engaged" and "e-stop" in refusal.reason
        assert state.view()["controls"][cid] == {"enabled": False, "reason": refusal.reason,
                                                 "reason_i18n": refusal.reason.wire()}
    assert state.refusal(control(state, "stop")) is None  # allowed_during_estop
    assert state.view()["controls"]["stop"]["enabled"] is True
    assert panel.on_estop == "stop"
