"""The simulated rover's health: every diagnostic level and every log level shows up in a demo's first minutes."""

from rover_web.sim.health import HealthModel


def test_statuses_degrade_and_logs_use_every_level():
    model = HealthModel()
    levels, log_levels, names = set(), set(), set()
    for _ in range(300):
        statuses, logs = model.step()
        levels.update(s["level"] for s in statuses)
        names.update(s["hardware_id"] for s in statuses)
        log_levels.update(level for level, _ in logs)
    assert levels == {0, 1, 2}
    assert names == {"battery", "motor_controller", "gps"}
    assert log_levels == {"debug", "info", "warning", "error", "fatal"}
