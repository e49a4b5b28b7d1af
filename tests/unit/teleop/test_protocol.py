"""Teleop WebSocket frames: what is accepted, what gets an error frame, what closes the socket."""

import json
from unittest import mock

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.teleop import protocol as teleop_protocol
from rover_web.teleop.protocol import Control, Drive, FrameError, Pong, parse_frame
from rover_web.web.validate import loads_strict

MAX = 4096


def test_drive_frames():
    assert parse_frame('{"linear": 0.5, "angular": -1}', MAX) == Drive(0.5, -1.0, 0, "joystick")
    assert parse_frame('{"linear": 0, "angular": 0, "epoch": 3, "source": "keyboard"}', MAX) == \
        Drive(0.0, 0.0, 3, "keyboard")
    assert parse_frame('{"linear": -0.25, "angular": 1, "epoch": 2, "source": "gamepad"}', MAX) == \
        Drive(-0.25, 1.0, 2, "gamepad")
    assert parse_frame('{"linear": 0.5, "angular": 0, "seq": 17, "t": 123456.789}', MAX) == \
        Drive(0.5, 0.0, 0, "joystick", 17, 123456.789)
    assert parse_frame('{"linear": 0.5, "angular": 0, "seq": 0, "t": 0}', MAX) == Drive(0.5, 0.0, seq=0, t=0.0)


@pytest.mark.parametrize("action", ["stop", "takeover", "release"])
def test_control_frames(action):
    assert parse_frame(json.dumps({action: True}), MAX) == Control(action)


def test_a_pong_names_the_ping_it_answers():
    assert parse_frame('{"pong": 7}', MAX) == Pong(7)
    for bad in ('{"pong": true}', '{"pong": -1}', '{"pong": 4294967296}', '{"pong": 1, "seq": 2}'):
        with pytest.raises(FrameError):
            parse_frame(bad, MAX)


def test_a_stop_may_carry_a_seq_other_controls_may_not():
    assert parse_frame('{"stop": true, "seq": 9}', MAX) == Control("stop", 9)
    for bad in ('{"stop": true, "seq": -1}', '{"stop": true, "seq": 1.5}', '{"stop": true, "seq": null}',
                '{"takeover": true, "seq": 3}', '{"stop": true, "t": 3}'):
        with pytest.raises(FrameError):
            parse_frame(bad, MAX)


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
    ('{"linear": 0, "angular": 0, "source": "joypad"}', "bad_value"),
    ('{"linear": 0, "angular": 0, "source": "Gamepad"}', "bad_value"),
    ('{"linear": 0, "angular": 0, "seq": -1}', "bad_type"),
    ('{"linear": 0, "angular": 0, "seq": 1.5}', "bad_type"),
    ('{"linear": 0, "angular": 0, "seq": true}', "bad_type"),
    ('{"linear": 0, "angular": 0, "seq": null}', "bad_type"),
    ('{"linear": 0, "angular": 0, "seq": "3"}', "bad_type"),
    ('{"linear": 0, "angular": 0, "seq": 9007199254740992}', "bad_type"),
    ('{"linear": 0, "angular": 0, "t": "12"}', "bad_type"),
    ('{"linear": 0, "angular": 0, "t": null}', "bad_type"),
    ('{"linear": 0, "angular": 0, "t": false}', "bad_type"),
    ('{"linear": 0, "angular": 0, "t": -0.5}', "out_of_range"),
    ('{"linear": 0, "angular": 0, "t": 1e300}', "out_of_range"),
    ('{"linear": 0, "angular": 0, "t": NaN}', "non_finite"),
    ('{"linear": 0, "angular": 0, "t": 1e400}', "non_finite"),
    ('{"release": true, "seq": 3}', "unknown_field"),
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


# --- orjson, with the standard decoder behind it, decides every frame as the standard one alone ---

json_numbers = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False), st.floats(min_value=-1.0, max_value=1.0),
    st.integers(), st.integers(min_value=-10 ** 400, max_value=10 ** 400),
    st.sampled_from([2 ** 63, 2 ** 64, -2 ** 63 - 1]))
json_values = st.recursive(
    st.one_of(json_numbers, st.booleans(), st.none(), st.text(max_size=8)),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner, max_size=3), max_leaves=8)
frame_keys = st.sampled_from(["linear", "angular", "epoch", "source", "seq", "t", "stop", "takeover", "release", "x",
                              "\ud800"])
frame_texts = st.one_of(
    st.dictionaries(frame_keys, json_values, max_size=5).map(json.dumps),
    st.fixed_dictionaries({"linear": json_numbers, "angular": json_numbers},
                          optional={"epoch": json_numbers, "seq": json_numbers, "t": json_numbers,
                                    "source": st.sampled_from(["joystick", "keyboard", "gamepad", "\ud800"])}
                          ).map(json.dumps),
    json_values.map(json.dumps),
    st.tuples(st.sampled_from(['{"linear": %s, "angular": 0}', '{"epoch": %s, "linear": 0, "angular": 0}', '[%s]',
                               '{"linear": 0, "angular": 0, "seq": %s}', '{"linear": 0, "angular": 0, "t": %s}']),
              st.sampled_from(["NaN", "-Infinity", "1e400", "-1e999", "1" + "0" * 400, "0.1e-400", "01", "1.", "-",
                               '"\\ud800"', "1E+2", "-0", "true", "null"])).map(lambda t: t[0] % t[1]),
    st.text(max_size=30),
)


def outcome(text):
    try:
        return ("ok", parse_frame(text, MAX))
    except FrameError as exc:
        return ("error", exc.code, exc.message, exc.close_code)


@settings(max_examples=1500, deadline=None)
@given(frame_texts)
def test_orjson_and_the_standard_decoder_decide_every_frame_alike(text):
    fast = outcome(text)
    with mock.patch.object(teleop_protocol, "_loads", loads_strict):
        standard = outcome(text)
    assert fast == standard
