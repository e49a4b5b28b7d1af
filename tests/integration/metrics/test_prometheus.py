"""A real Prometheus (Debian's `prometheus`, scripts/bootstrap.sh --browser) on 127.0.0.1 scrapes a
real rover_web (flask run, with the simulator) and a real hub (which hears that rover_web over
Zenoh): docs/alerts.yml passes `promtool check rules`, and RoverBatteryLow fires when the
simulator's battery is low and resolves when it recovers.

The rules loaded are docs/alerts.yml's own, copied with every `for:` at 1 s (a test cannot wait
two minutes); the expressions and thresholds are the shipped ones. "Driven low": the simulator is
started with a 12 % pack (`--battery 12`), then replaced by one with a full pack, as an operator
swapping batteries would (`--battery 95`). Scrapes and rule evaluation every second.
"""

from __future__ import annotations

import os
import secrets
import shutil
import subprocess
import time
from pathlib import Path

import pytest
import requests
import yaml

from tests.conftest import ROOT, ServerProcess, SimProcess, free_port
from tests.support.auth import add_users
from tests.support.waiting import wait_until

PROMETHEUS = shutil.which("prometheus")
PROMTOOL = shutil.which("promtool")
RULES = Path(ROOT) / "docs" / "alerts.yml"

pytestmark = pytest.mark.skipif(not (PROMETHEUS and PROMTOOL),
                                reason="Debian's prometheus is not installed: scripts/bootstrap.sh --browser")


def test_the_shipped_rules_pass_promtool():
    result = subprocess.run([PROMTOOL, "check", "rules", str(RULES)], capture_output=True, text=True, timeout=30)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "SUCCESS" in result.stdout


def test_the_rules_fire_and_stay_quiet_as_written_on_synthetic_series():
    """promtool's rule tests (alerts_test.yml): the shipped `for:` durations, the thresholds, the
    labels and annotations, for battery, e-stop, silent topic, recording stopped by a limit, lost."""
    tests = Path(__file__).with_name("alerts_test.yml")
    result = subprocess.run([PROMTOOL, "test", "rules", str(tests)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr


def _fast_rules(path: Path) -> Path:
    rules = yaml.safe_load(RULES.read_text())
    for group in rules["groups"]:
        group["interval"] = "1s"
        for rule in group["rules"]:
            if "for" in rule:
                rule["for"] = "1s"
    path.write_text(yaml.safe_dump(rules))
    return path


def _alerts(prom_url: str, name: str) -> list[dict]:
    alerts = requests.get(f"{prom_url}/api/v1/alerts", timeout=5).json()["data"]["alerts"]
    return [a for a in alerts if a["labels"]["alertname"] == name]


def _query(prom_url: str, expr: str) -> list[dict]:
    return requests.get(f"{prom_url}/api/v1/query", params={"query": expr}, timeout=5).json()["data"]["result"]


def test_an_alert_fires_when_the_battery_is_low_and_resolves_when_it_recovers(tmp_path):
    domain = str((int(os.environ["ROS_DOMAIN_ID"]) + 70) % 200 + 1)
    key_file = tmp_path / "fleet.key"
    key_file.write_text(secrets.token_hex(32))
    key_file.chmod(0o600)
    zenoh_endpoint = f"tcp/127.0.0.1:{free_port()}"
    hub_db = tmp_path / "hub.sqlite3"
    tokens = add_users(hub_db)
    hub = ServerProcess(env={"ROVER_WEB_HUB": "true", "ROVER_WEB_ZENOH_MODE": "peer",
                             "ROVER_WEB_ZENOH_LISTEN": zenoh_endpoint, "ROVER_WEB_FLEET_NAME": "promfleet",
                             "ROVER_WEB_FLEET_KEY_FILE": str(key_file), "ROVER_WEB_AUTH": "required",
                             "ROVER_WEB_DB_PATH": str(hub_db)})
    robot = ServerProcess(env={"ROS_DOMAIN_ID": domain, "ROVER_WEB_ZENOH_MODE": "peer",
                               "ROVER_WEB_ZENOH_CONNECT": zenoh_endpoint,
                               "ROVER_WEB_ZENOH_LISTEN": f"tcp/127.0.0.1:{free_port()}",
                               "ROVER_WEB_FLEET_NAME": "promfleet", "ROVER_WEB_FLEET_KEY_FILE": str(key_file),
                               "ROVER_WEB_DB_PATH": str(tmp_path / "robot.sqlite3"),
                               "ROVER_WEB_RECORDINGS_DIR": str(tmp_path / "recordings")})
    prom_port = free_port()
    prom_url = f"http://127.0.0.1:{prom_port}"
    sims: list[SimProcess] = []
    prometheus = None
    try:
        sims.append(SimProcess(["--only", "rover", "--battery", "12"], ROS_DOMAIN_ID=domain))
        hub.start()
        robot.start()
        token_file = tmp_path / "hub.token"
        token_file.write_text(tokens["viewer"])
        config = {
            "global": {"scrape_interval": "1s", "evaluation_interval": "1s", "scrape_timeout": "900ms"},
            "rule_files": [str(_fast_rules(tmp_path / "alerts.yml"))],
            "scrape_configs": [
                {"job_name": "rover_web", "static_configs": [{"targets": [f"127.0.0.1:{robot.port}"]}]},
                # The hub has sign-in on: Prometheus' bearer credentials, a viewer's API token.
                {"job_name": "rover_web_hub", "authorization": {"credentials_file": str(token_file)},
                 "static_configs": [{"targets": [f"127.0.0.1:{hub.port}"]}]},
            ],
        }
        (tmp_path / "prometheus.yml").write_text(yaml.safe_dump(config))
        with open(tmp_path / "prometheus.log", "w") as log:  # the child keeps its own descriptor
            prometheus = subprocess.Popen([PROMETHEUS, f"--config.file={tmp_path / 'prometheus.yml'}",
                                           f"--storage.tsdb.path={tmp_path / 'tsdb'}",
                                           f"--web.listen-address=127.0.0.1:{prom_port}"],
                                          stdout=log, stderr=subprocess.STDOUT)
        wait_until(lambda: _ready(prom_url), timeout=15, what="Prometheus ready")
        wait_until(lambda: {t["labels"]["job"]: t["health"] for t in requests.get(
            f"{prom_url}/api/v1/targets", timeout=5).json()["data"]["activeTargets"]} ==
            {"rover_web": "up", "rover_web_hub": "up"}, timeout=10, what="both targets scraped and up")
        # The hub's figures, from what it heard over Zenoh: the robot live, its battery.
        wait_until(lambda: _query(prom_url, 'rover_web_hub_robot_state{robot="robot",state="live"} == 1'),
                   timeout=15, what="the hub's robot live in Prometheus")
        firing = wait_until(lambda: [a for a in _alerts(prom_url, "RoverBatteryLow") if a["state"] == "firing"],
                            timeout=15, what="RoverBatteryLow firing")
        assert firing[0]["labels"]["robot"] == "robot" and firing[0]["labels"]["severity"] == "warning"
        assert 11 < float(firing[0]["value"]) < 12.5
        assert not _alerts(prom_url, "RoverBatteryCritical")  # 12 % is low, not critical
        # A fresh pack: the simulator restarted with 95 %.
        sims.pop().stop()
        sims.append(SimProcess(["--only", "rover", "--battery", "95"], ROS_DOMAIN_ID=domain))
        wait_until(lambda: not _alerts(prom_url, "RoverBatteryLow"), timeout=15, what="RoverBatteryLow resolved")
        assert float(_query(prom_url, "rover_web_battery_percent")[0]["value"][1]) > 90
    finally:
        if prometheus is not None:
            prometheus.terminate()
            try:
                prometheus.wait(10)
            except subprocess.TimeoutExpired:
                prometheus.kill()
        for sim in sims:
            sim.stop()
        robot.stop()
        hub.stop()


def _ready(url: str) -> bool:
    try:
        return requests.get(f"{url}/-/ready", timeout=1).status_code == 200
    except requests.RequestException:
        time.sleep(0.1)
        return False
