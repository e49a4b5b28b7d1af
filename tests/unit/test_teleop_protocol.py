"""Teleop WebSocket frames: what is accepted, what gets an error frame, what closes the socket."""

import json

import pytest

from rover_web.teleop_protocol import Control, Drive, FrameError, parse_frame

MAX = 4096


def test_drive_frames():
    assert parse_frame('{"linear": 0.5, "angular": -1}', MAX) == Drive(0.5, -1.0, 0, "joystick")
    assert parse_frame('{"linear": 0, "angular": 0, "epoch": 3, "source": "keyboard"}', MAX) == \
        Drive(0.0, 0.0, 3, "keyboard")


@pytest.mark.parametrize("action", ["stop", "takeover", "release"])
def test_control_frames(action):
    assert parse_frame(json.dumps({action: True}), MAX) == Control(action)


@pytest.mark.parametrize("text, code", [
    ('{"linear": NaN, "angular": 0}', "non_finite"),
    ('{"linear": Infinity, "angular": 0}', "non_finite"),
    ('{"linear": -Infinity, "angular": 0}', "non_finite"),
    ('{"linear": 1e400, "angular": 0}', "non_finite"),
    ('{"linear": "1", "angular": 0}', "bad_type"),
    ('{"linear": null, "angular": 0}', "bad_type"),
    ('{"linear": true, "angular": 0}', "bad_type"),
    ('{"linear": 0.5}', "missing_field"),
    ('{"angular": 0.5}', "missing_field"),
    ('{"linear": 1.01, "angular": 0}', "out_of_range"),
    ('{"linear": 0, "angular": -2}', "out_of_range"),
    ('{"linear": 0, "angular": 0, "speed": 1}', "unknown_field"),
    ('{"linear": 0, "angular": 0, "epoch": -1}', "bad_type"),
    ('{"linear": 0, "angular": 0, "epoch": 1.5}', "bad_type"),
    ('{"linear": 0, "angular": 0, "source": "gamepad"}', "bad_value"),
    ('{"stop": false}', "bad_value"),
    ('{"stop": true, "linear": 1}', "unknown_field"),
    ('[0.5, 0.5]', "bad_frame"),
    ('"forward"', "bad_frame"),
    ('null', "bad_frame"),
    ('{}', "missing_field"),
])
def test_bad_content_gets_an_error_frame(text, code):
    with pytest.raises(FrameError) as info:
        parse_frame(text, MAX)
    assert info.value.code == code and info.value.close_code is None
    assert info.value.as_frame()["type"] == "error"


@pytest.mark.parametrize("data, close_code", [
    ("{linear: 1}", 1007),
    ("not json", 1007),
    ("", 1007),
    (b'{"linear": 1, "angular": 0}', 1003),
    ('{"linear": 0, "angular": 0, "pad": "' + "x" * 5000 + '"}', 1009),
    ('{"linear": 0, "angular": 0, "pad": "' + "é" * 2100 + '"}', 1009),  # 2100 chars, 4200 bytes
    (b"x" * 5000, 1009),
])
def test_broken_frames_close_the_socket(data, close_code):
    with pytest.raises(FrameError) as info:
        parse_frame(data, MAX)
    assert info.value.close_code == close_code


def test_limit_is_inclusive():
    frame = '{"linear": 0, "angular": 0}'
    padded = frame[:-1] + ' ' * (MAX - len(frame)) + '}'
    assert len(padded.encode()) == MAX
    assert parse_frame(padded, MAX) == Drive(0.0, 0.0)
