"""The simulated robot's battery: a 6-cell Li-ion pack that drains with what the robot does.

The model is pure Python (unit-tested); `battery_state()` fills the sensor_msgs/BatteryState the
robot publishes, so the GUI's "% · V", the diagnostics and the log lines all read one number.

Numbers, chosen so a demo shows the drain within a minute of driving: 10 Ah at 22.2 V nominal;
1.5 A at rest (computers, radio), plus 12 A per m/s and 3 A per rad/s. At rest the pack lasts
hours (1 % in about 4 min); driving at 1 m/s takes 1 % in about 27 s. The voltage is the cell's
open-circuit curve times six, less the sag of the draw through 60 mΩ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise

from sensor_msgs.msg import BatteryState

CELLS = 6
CAPACITY_AH = 10.0
IDLE_A, PER_MPS_A, PER_RPS_A = 1.5, 12.0, 3.0
INTERNAL_OHM = 0.06
# A Li-ion cell's open-circuit volts by state of charge: flat in the middle, steep at both ends.
CELL_OCV = ((0.0, 3.30), (0.05, 3.45), (0.10, 3.55), (0.20, 3.65), (0.50, 3.80), (0.80, 4.00), (1.0, 4.20))
START_CHARGE = 0.8  # a robot that has done some work today, so the card never reads a suspicious 100 %


def cell_ocv(charge: float) -> float:
    """Open-circuit volts of one cell at `charge` (0..1), interpolated on CELL_OCV."""
    charge = min(1.0, max(0.0, charge))
    for (c0, v0), (c1, v1) in pairwise(CELL_OCV):
        if charge <= c1:
            return v0 + (v1 - v0) * (charge - c0) / (c1 - c0)
    return CELL_OCV[-1][1]


@dataclass
class Battery:
    charge: float = START_CHARGE  # 0..1 of CAPACITY_AH
    current_a: float = IDLE_A     # the draw, positive while discharging

    def drain(self, dt_s: float, speed_mps: float, turn_rps: float) -> None:
        """Draw for `dt_s` seconds at this speed and turn rate (magnitudes)."""
        self.current_a = IDLE_A + PER_MPS_A * abs(speed_mps) + PER_RPS_A * abs(turn_rps)
        self.charge = max(0.0, self.charge - self.current_a * dt_s / 3600.0 / CAPACITY_AH)

    def swap(self) -> None:
        self.charge = 1.0

    @property
    def percent(self) -> float:
        return 100.0 * self.charge

    @property
    def cell_v(self) -> float:
        return cell_ocv(self.charge) - self.current_a * INTERNAL_OHM / CELLS

    @property
    def voltage(self) -> float:
        return CELLS * self.cell_v


def battery_state(battery: Battery, stamp) -> BatteryState:
    msg = BatteryState()
    msg.header.stamp = stamp
    msg.header.frame_id = "base_link"
    msg.voltage = float(battery.voltage)
    msg.temperature = math.nan  # no sensor: NaN is "unknown" in BatteryState
    msg.current = -float(battery.current_a)  # negative while discharging, as the message defines
    msg.charge = float(battery.charge * CAPACITY_AH)
    msg.capacity = msg.design_capacity = CAPACITY_AH
    msg.percentage = float(battery.charge)
    msg.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
    msg.power_supply_health = BatteryState.POWER_SUPPLY_HEALTH_GOOD
    msg.power_supply_technology = BatteryState.POWER_SUPPLY_TECHNOLOGY_LION
    msg.present = True
    msg.cell_voltage = [float(battery.cell_v)] * CELLS
    msg.cell_temperature = [math.nan] * CELLS
    msg.location = "main"
    return msg
