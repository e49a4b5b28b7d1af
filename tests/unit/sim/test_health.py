"""The simulated rover's health: every diagnostic level shows up, errors stay rare, the log agrees with the battery."""

from rover_web.sim.battery import Battery
from rover_web.sim.health import ERROR, MOTOR_FAULT_EVERY_S, HealthModel


def run(model: HealthModel, seconds: int, speed_mps: float = 0.0):
    for _ in range(seconds):
        statuses, logs = model.step(speed_mps)
        yield statuses, logs


def test_an_hour_at_rest_shows_every_diagnostic_level_and_only_two_error_lines():
    levels, names, errors, log_levels = set(), set(), [], set()
    for statuses, logs in run(HealthModel(), 3600):
        levels.update(s["level"] for s in statuses)
        names.update(s["hardware_id"] for s in statuses)
        log_levels.update(level for level, _ in logs)
        errors += [text for level, text in logs if level in ("error", "fatal")]
    assert levels == {0, 1, 2}
    assert names == {"battery", "motor_controller", "gps"}
    assert log_levels == {"debug", "info", "warning", "error"}
    # One scripted fault every 30 minutes: the Errors pill (errors in the last minute) is almost always 0.
    assert errors == ["left motor controller tripped on overcurrent; resetting"] * (3600 // MOTOR_FAULT_EVERY_S)


def test_the_first_error_comes_after_a_quarter_of_an_hour():
    first = next(i for i, (_, logs) in enumerate(run(HealthModel(), 3600)) if any(lv == "error" for lv, _ in logs))
    assert first == 900


def battery_status(statuses):
    return next(s for s in statuses if s["hardware_id"] == "battery")


def test_the_battery_drains_faster_while_driving_and_the_diagnostics_show_its_numbers():
    resting, driving = HealthModel(), HealthModel()
    list(run(resting, 60))
    statuses, _ = list(run(driving, 60, speed_mps=1.0))[-1]
    assert 80 - driving.battery.percent > 5 * (80 - resting.battery.percent) > 0  # 13.5 A against 1.5 A
    status = battery_status(statuses)
    assert status["values"]["voltage_V"] == f"{driving.battery.voltage:.2f}"
    assert status["values"]["percent"] == f"{driving.battery.percent:.0f}"


def test_the_log_says_low_and_critical_exactly_when_the_battery_is():
    model = HealthModel(battery=Battery(charge=0.205))
    said = []
    for statuses, logs in run(model, 3000, speed_mps=2.0):
        said += [(level, text, battery_status(statuses)["level"]) for level, text in logs if "battery" in text]
        if any("swaps in a full one" in text for _, text in logs):
            break
    levels = [(level, status) for level, _, status in said]
    assert levels[:3] == [("info", 0), ("warning", 1), ("error", ERROR)]
    assert said[1][1].startswith("battery low: 19 %") and said[2][1].startswith("battery critically low: 9 %")
    assert model.battery.percent == 100.0  # swapped at 3 %


def test_a_robot_that_starts_low_says_so_in_its_first_second():
    model = HealthModel(battery=Battery(charge=0.09))
    _, logs = model.step()
    assert logs[0] == ("error", f"battery critically low: 9 % ({model.battery.voltage:.2f} V)")
