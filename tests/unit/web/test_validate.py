import pytest

from rover_web.web.validate import InvalidInput, loads_strict, number, only_keys, text


@pytest.mark.parametrize("raw", ['{"x": NaN}', '{"x": Infinity}', '{"x": -Infinity}', '{"x": 1e400}', '[-1e999]'])
def test_non_finite_numbers_are_refused(raw):
    with pytest.raises(InvalidInput) as err:
        loads_strict(raw)
    assert err.value.code == "non_finite"


@pytest.mark.parametrize("raw", ["{", "", "\xff", b"\xff\xfe", "[" * 100000])
def test_malformed_json_is_bad_json(raw):
    with pytest.raises(InvalidInput) as err:
        loads_strict(raw)
    assert err.value.code == "bad_json"


def test_number_checks_type_range_and_default():
    assert number({"v": 1}, "v", low=0, high=2) == 1.0
    assert number({}, "v", default=0.5) == 0.5
    for bad, code in [({"v": True}, "bad_type"), ({"v": "1"}, "bad_type"), ({"v": None}, "bad_type"),
                      ({"v": 3}, "out_of_range"), ({}, "missing_field"),
                      ({"v": 10 ** 400}, "out_of_range"), ({"v": -10 ** 400}, "out_of_range")]:  # no OverflowError
        with pytest.raises(InvalidInput) as err:
            number(bad, "v", low=0, high=2)
        assert err.value.code == code


def test_text_and_only_keys():
    assert text({"c": "stop"}, "c", choices=("stop",)) == "stop"
    with pytest.raises(InvalidInput, match="one of"):
        text({"c": "jump"}, "c", choices=("stop",))
    with pytest.raises(InvalidInput, match="longer than"):
        text({"c": "x" * 300}, "c")
    with pytest.raises(InvalidInput, match="unknown field"):
        only_keys({"a": 1, "b": 2}, {"a"})


@pytest.mark.parametrize("name", ["/cmd_vel\n", "/a\n/b", "\n/cmd_vel", " /cmd_vel", "/cmd_vel ", "/a\r/b"])
def test_topic_names_with_line_breaks_or_spaces_are_bad_topics(name):
    """`$` also matches before a trailing newline: '/a\\n/b' passed the token check and reached rclpy."""
    from rover_web.web.validate import topic_name

    with pytest.raises(InvalidInput) as caught:
        topic_name(name)
    assert caught.value.code == "bad_topic"


def test_every_name_pattern_refuses_a_trailing_newline():
    """Each pattern that accepts a name must refuse that name with a newline after it."""
    from rover_web.config import TOPIC_PATTERN
    from rover_web.events.hub import CHANNEL_RE
    from rover_web.panels.file_fields import ID_RE
    from rover_web.panels.scalars import _TYPE_NAME_RE
    from rover_web.scan_the_code.light_sequence import COLOUR_NAME_RE

    for pattern, good in [(TOPIC_PATTERN, "/cmd_vel"), (CHANNEL_RE, "telemetry"), (ID_RE, "drone"),
                          (_TYPE_NAME_RE, "std_msgs/msg/Int8"), (COLOUR_NAME_RE, "red")]:
        assert pattern.match(good), pattern.pattern
        assert not pattern.match(good + "\n"), pattern.pattern


def test_no_pattern_in_the_code_ends_with_a_dollar():
    """The slip, found once, kept out: a regex literal ending in `$` inside rover_web/."""
    import re
    from pathlib import Path

    import rover_web

    literal = re.compile(r"""re\.compile\(\s*r?["'](?P<body>.*?)["']\s*[,)]""")
    offenders = [f"{path.name}: {m['body']}"
                 for path in Path(rover_web.__file__).parent.rglob("*.py")
                 for m in literal.finditer(path.read_text()) if m["body"].endswith("$")]
    assert offenders == []
