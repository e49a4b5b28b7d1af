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
