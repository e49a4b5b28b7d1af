"""Names and small HTTP helpers for the two-robot tests (fixtures are in conftest.py)."""

from __future__ import annotations

import requests

ROBOTS = [{"name": "boat"}, {"name": "drone"}]
NAMES = ("boat", "drone")
CMD_VEL = {"boat": "/boat/cmd_vel", "drone": "/drone/cmd_vel"}
ROOT_CMD_VEL = "/cmd_vel"  # where a robot without a namespace would drive: nothing may go there


def post(url: str, body: dict | None = None) -> requests.Response:
    return requests.post(url, json={} if body is None else body, timeout=5)


def get(url: str) -> dict:
    response = requests.get(url, timeout=5)
    response.raise_for_status()
    return response.json()
