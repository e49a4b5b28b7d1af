"""Reading recordings back in tests, with each reader the docs promise works."""

from __future__ import annotations

import json
from pathlib import Path

import requests

from tests.support.waiting import wait_until

STRING = "std_msgs/msg/String"
ODOM = "nav_msgs/msg/Odometry"


def start(server, body: dict, headers=None) -> dict:
    answer = requests.post(server.url + "/api/recordings", json=body, headers=headers, timeout=10)
    assert answer.status_code == 201, answer.text
    return answer.json()


def status(server, recording_id: str) -> dict:
    return requests.get(f"{server.url}/api/recordings/{recording_id}", timeout=5).json()


def stop(server, recording_id: str) -> dict:
    answer = requests.post(f"{server.url}/api/recordings/{recording_id}/stop", json={}, timeout=15)
    assert answer.status_code == 200, answer.text
    return answer.json()


def wait_listed(server, topic: str) -> None:
    wait_until(lambda: any(t["name"] == topic for t in
                           requests.get(server.url + "/api/topics", timeout=5).json()["topics"]), 15, f"{topic} listed")


def read_mcap_ros2(path: Path) -> dict[str, list]:
    """topic -> decoded messages, in order, by mcap-ros2-support's decoder (the seeking reader)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    found: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, channel, _message, decoded in reader.iter_decoded_messages():
            found.setdefault(channel.topic, []).append(decoded)
    return found


def read_rosbags(path: Path) -> dict[str, list]:
    """topic -> deserialized messages, in order, by rosbags' AnyReader on the .mcap file."""
    from rosbags.highlevel import AnyReader

    found: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for connection, _t, raw in reader.messages():
            found.setdefault(connection.topic, []).append(reader.deserialize(raw, connection.msgtype))
    return found


def audit_records(decoded: list) -> list[dict]:
    return [json.loads(m.data) for m in decoded]
