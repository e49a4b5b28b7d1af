"""The simulated rover's health: battery, motors and GPS fix quality, one of them degrading now and then. Pure Python.

Each second `step()` gives the diagnostic statuses (as plain dicts) and the log lines that go with
them, so the demo's /diagnostics and /logs pages show every level: a battery that drains and is
swapped, a motor that runs hot for a while, GPS corrections that drop out.
"""

from __future__ import annotations

from dataclasses import dataclass

OK, WARN, ERROR = 0, 1, 2
BATTERY_FULL_V, BATTERY_EMPTY_V = 25.2, 22.0
BATTERY_CYCLE_S = 300  # drained, then "swapped"
MOTOR_HOT_EVERY_S, MOTOR_HOT_FOR_S = 45, 10
GPS_DROP_EVERY_S, GPS_DROP_FOR_S = 70, 8


@dataclass
class HealthModel:
    node: str = "sim_rover"  # names the statuses, as diagnostic_updater does ("node: task")
    t: int = 0  # seconds since start

    def battery_v(self) -> float:
        phase = (self.t % BATTERY_CYCLE_S) / BATTERY_CYCLE_S
        return round(BATTERY_FULL_V - (BATTERY_FULL_V - BATTERY_EMPTY_V) * phase, 2)

    def step(self) -> tuple[list[dict], list[tuple[str, str]]]:
        """(statuses, [(level, text)]) for this second; then the clock moves on."""
        t = self.t
        logs: list[tuple[str, str]] = []
        volts = self.battery_v()
        battery_level = OK if volts >= 23.0 else WARN if volts >= 22.4 else ERROR
        hot = t % MOTOR_HOT_EVERY_S >= MOTOR_HOT_EVERY_S - MOTOR_HOT_FOR_S
        temp_c = 71.5 if hot else 42.0
        no_rtk = t % GPS_DROP_EVERY_S >= GPS_DROP_EVERY_S - GPS_DROP_FOR_S
        statuses = [
            {"name": f"{self.node}: battery", "hardware_id": "battery", "level": battery_level,
             "message": {OK: "ok", WARN: "low", ERROR: "critically low"}[battery_level],
             "values": {"voltage_V": f"{volts:.2f}", "percent": f"{100 * (volts - 22.0) / 3.2:.0f}"}},
            {"name": f"{self.node}: left motor", "hardware_id": "motor_controller", "level": WARN if hot else OK,
             "message": "running hot" if hot else "ok", "values": {"temperature_C": f"{temp_c:.1f}"}},
            {"name": f"{self.node}: right motor", "hardware_id": "motor_controller", "level": OK, "message": "ok",
             "values": {"temperature_C": "41.0"}},
            {"name": f"{self.node}: gps", "hardware_id": "gps", "level": WARN if no_rtk else OK,
             "message": "no RTK corrections: float fix" if no_rtk else "RTK fixed",
             "values": {"fix": "float" if no_rtk else "rtk_fixed", "satellites": "9" if no_rtk else "17"}},
        ]
        if t % 5 == 0:
            logs.append(("debug", f"health check {t}: {volts:.2f} V, motors {temp_c:.0f} C"))
        if t % 10 == 0:
            logs.append(("info", f"battery at {volts:.2f} V"))
        if hot and t % MOTOR_HOT_EVERY_S == MOTOR_HOT_EVERY_S - MOTOR_HOT_FOR_S:
            logs.append(("warning", f"left motor running hot ({temp_c:.1f} C)"))
        if no_rtk and t % GPS_DROP_EVERY_S == GPS_DROP_EVERY_S - GPS_DROP_FOR_S:
            logs.append(("error", "GPS RTK corrections lost"))
        if battery_level == ERROR and t % 10 == 0:
            logs.append(("error", f"battery critically low: {volts:.2f} V"))
        if t % BATTERY_CYCLE_S == BATTERY_CYCLE_S - 1:
            logs.append(("fatal", "battery empty: the simulated rover swaps in a full one (demo only)"))
        self.t += 1
        return statuses, logs
