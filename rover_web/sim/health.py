"""The simulated rover's health: battery, motors and GPS fix quality, one of them degrading now and then. Pure Python.

Each second `step()` gives the diagnostic statuses (as plain dicts) and the log lines that go with
them. The battery is the one the robot publishes on battery_state (battery.py), so the Robot card,
the diagnostics and the log always agree. Faults are scripted on fixed periods, rare enough that
the Errors pill (errors in the last minute) means something, as on a real robot:

- GPS RTK corrections drop (WARN, float fix) for 10 s every 7 min, first after 2 min;
- the left motor runs hot (WARN) for 20 s every 10 min, first after 4 min;
- the left motor controller trips on overcurrent (ERROR) for 5 s every 30 min, first after 15 min:
  the only scripted ERROR line;
- the battery warns once below 20 % and logs an ERROR once below 10 % (after about half an hour of
  driving), and at 3 % the demo swaps in a full pack.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .battery import Battery

OK, WARN, ERROR = 0, 1, 2
BATTERY_LOW, BATTERY_CRITICAL, BATTERY_SWAP = 20.0, 10.0, 3.0  # percent
GPS_FLOAT_EVERY_S, GPS_FLOAT_AT_S, GPS_FLOAT_FOR_S = 420, 120, 10
MOTOR_HOT_EVERY_S, MOTOR_HOT_AT_S, MOTOR_HOT_FOR_S = 600, 240, 20
MOTOR_FAULT_EVERY_S, MOTOR_FAULT_AT_S, MOTOR_FAULT_FOR_S = 1800, 900, 5
DEBUG_EVERY_S = 5


def _window(t: int, every: int, at: int, length: int) -> tuple[bool, bool, bool]:
    """(inside, starts now, ends now) of an event that runs `length` s from `at` in each `every` s."""
    phase = t % every
    return at <= phase < at + length, phase == at, phase == at + length


def battery_level(percent: float) -> int:
    percent = round(percent)  # as the Robot card shows it, so "low" never comes with "20 %"
    return OK if percent >= BATTERY_LOW else WARN if percent >= BATTERY_CRITICAL else ERROR


@dataclass
class HealthModel:
    node: str = "sim_rover"  # names the statuses, as diagnostic_updater does ("node: task")
    t: int = 0  # seconds since start
    battery: Battery = field(default_factory=Battery)

    def step(self, speed_mps: float = 0.0, turn_rps: float = 0.0) -> tuple[list[dict], list[tuple[str, str]]]:
        """(statuses, [(level, text)]) for this second, the battery drained by this speed; then the clock moves on."""
        t = self.t
        logs: list[tuple[str, str]] = []
        logs += self._drain(speed_mps, turn_rps)
        percent, volts = self.battery.percent, self.battery.voltage
        level = battery_level(percent)
        no_rtk, rtk_lost, rtk_back = _window(t, GPS_FLOAT_EVERY_S, GPS_FLOAT_AT_S, GPS_FLOAT_FOR_S)
        hot, hot_starts, hot_ends = _window(t, MOTOR_HOT_EVERY_S, MOTOR_HOT_AT_S, MOTOR_HOT_FOR_S)
        fault, tripped, reset = _window(t, MOTOR_FAULT_EVERY_S, MOTOR_FAULT_AT_S, MOTOR_FAULT_FOR_S)
        temp_c = 71.5 if hot else 42.0
        left = (ERROR, "overcurrent trip: resetting") if fault else (WARN, "running hot") if hot else (OK, "ok")
        statuses = [
            {"name": f"{self.node}: battery", "hardware_id": "battery", "level": level,
             "message": {OK: "ok", WARN: "low", ERROR: "critically low"}[level],
             "values": {"voltage_V": f"{volts:.2f}", "percent": f"{percent:.0f}",
                        "current_A": f"{self.battery.current_a:.1f}"}},
            {"name": f"{self.node}: left motor", "hardware_id": "motor_controller", "level": left[0],
             "message": left[1], "values": {"temperature_C": f"{temp_c:.1f}"}},
            {"name": f"{self.node}: right motor", "hardware_id": "motor_controller", "level": OK, "message": "ok",
             "values": {"temperature_C": "41.0"}},
            {"name": f"{self.node}: gps", "hardware_id": "gps", "level": WARN if no_rtk else OK,
             "message": "no RTK corrections: float fix" if no_rtk else "RTK fixed",
             "values": {"fix": "float" if no_rtk else "rtk_fixed", "satellites": "9" if no_rtk else "17"}},
        ]
        if t % DEBUG_EVERY_S == 0:
            logs.append(("debug", f"health check {t}: {percent:.1f} %, {volts:.2f} V, motors {temp_c:.0f} C"))
        if rtk_lost:
            logs.append(("warning", "GPS RTK corrections lost: float fix"))
        if rtk_back:
            logs.append(("info", "GPS RTK fixed again"))
        if hot_starts:
            logs.append(("warning", f"left motor running hot ({temp_c:.1f} C)"))
        if hot_ends:
            logs.append(("info", "left motor back to normal temperature"))
        if tripped:
            logs.append(("error", "left motor controller tripped on overcurrent; resetting"))
        if reset:
            logs.append(("info", "left motor controller reset: running"))
        self.t += 1
        return statuses, logs

    def _drain(self, speed_mps: float, turn_rps: float) -> list[tuple[str, str]]:
        """Drain one second's worth; a log line for each threshold the battery crosses."""
        battery = self.battery
        before = round(battery.percent)  # whole percent, as the Robot card and the log show it
        battery.drain(1.0, speed_mps, turn_rps)
        after = round(battery.percent)
        said = f"{after} % ({battery.voltage:.2f} V)"
        if self.t == 0:  # where it starts, so the log says from the first second what the card shows
            level = battery_level(after)
            return [({OK: "info", WARN: "warning", ERROR: "error"}[level],
                     f"battery {({OK: 'at', WARN: 'low:', ERROR: 'critically low:'})[level]} {said}")]
        if after <= BATTERY_SWAP:
            battery.swap()
            return [("info", f"battery at {said}: the simulated robot swaps in a full one (demo only)")]
        if before >= BATTERY_CRITICAL > after:
            return [("error", f"battery critically low: {said}")]
        if before >= BATTERY_LOW > after:
            return [("warning", f"battery low: {said}")]
        if before // 10 > after // 10:
            return [("info", f"battery at {said}")]
        return []
