"""The /rosout ring: bounded, filtered (level is a minimum), newest first, repeats grouped, batches for SSE."""

import pytest

from rover_web.logs.ring import LEVELS, LINE_OVERHEAD_BYTES, LogRing, line_bytes, parse_level


def line(msg, level="INFO", node="talker", stamp=0.0):
    return {"stamp": stamp, "level": LEVELS[level], "level_name": level, "node": node, "msg": msg,
            "file": "", "function": "", "line": 0}


def test_the_ring_keeps_only_the_newest_lines_after_100000():
    ring = LogRing(keep=5000)
    for i in range(100_000):
        ring.add(line(f"line {i}", stamp=i))
    assert len(ring) == 5000
    newest = ring.query(limit=5000)
    assert newest[0]["msg"] == "line 99999" and newest[-1]["msg"] == "line 95000"
    lines, skipped = ring.drain()  # and the pending batch is bounded too
    assert len(lines) == 250 and skipped == 100_000 - 250 and ring.last_seq == 100_000


def test_level_is_a_minimum_and_node_and_text_filter_case_insensitively():
    ring = LogRing(keep=100)
    ring.add(line("debugging", "DEBUG"))
    ring.add(line("all good", "INFO", node="planner"))
    ring.add(line("Battery low", "WARN", node="power"))
    ring.add(line("motor fault", "ERROR", node="base"))
    ring.add(line("dead", "FATAL", node="base"))
    assert [x["msg"] for x in ring.query(min_level=LEVELS["WARN"])] == ["dead", "motor fault", "Battery low"]
    assert [x["msg"] for x in ring.query(node="BASE")] == ["dead", "motor fault"]
    assert [x["msg"] for x in ring.query(contains="battery")] == ["Battery low"]
    assert [x["msg"] for x in ring.query(min_level=LEVELS["ERROR"], contains="motor")] == ["motor fault"]
    assert [x["msg"] for x in ring.query(limit=2)] == ["dead", "motor fault"]


def test_repeated_identical_lines_are_one_entry_with_a_count():
    ring = LogRing(keep=100)
    ring.add(line("start", stamp=1))
    for i in range(5):
        ring.add(line("retrying", "WARN", stamp=2 + i))
    ring.add(line("retrying", "WARN", node="other", stamp=10))  # another node: not the same line
    got = ring.query()
    assert [(x["msg"], x["node"], x["count"]) for x in got] == [
        ("retrying", "other", 1), ("retrying", "talker", 5), ("start", "talker", 1)]
    assert got[1]["stamp"] == 6 and got[1]["first_stamp"] == 2


def test_lines_since_the_last_drain_come_out_once_in_order_with_the_overflow_counted():
    ring = LogRing(keep=100, batch_max=3)
    for i in range(5):
        ring.add(line(f"m{i}"))
    lines, skipped = ring.drain()
    assert [x["msg"] for x in lines] == ["m0", "m1", "m2"] and skipped == 2
    assert ring.drain() == ([], 0)


def test_errors_in_the_last_minute_are_counted_and_age_out():
    now = [1000.0]
    ring = LogRing(keep=100, clock=lambda: now[0])
    ring.add(line("bad", "ERROR"))
    ring.add(line("worse", "FATAL"))
    ring.add(line("meh", "WARN"))
    assert ring.errors_last_minute() == 2
    now[0] += 61
    ring.add(line("again", "ERROR"))
    assert ring.errors_last_minute() == 1


@pytest.mark.parametrize("text,level", [("warn", 30), ("WARNING", 30), ("Error", 40), ("20", 20)])
def test_levels_by_name_or_number(text, level):
    assert parse_level(text) == level


@pytest.mark.parametrize("text", ["loud", "", "-1", "300", "1e3"])
def test_bad_levels_are_refused(text):
    with pytest.raises(ValueError):
        parse_level(text)


def test_the_ring_keeps_at_most_its_byte_budget_of_text_and_always_the_newest_line():
    ring = LogRing(keep=5000, max_bytes=100_000)
    for i in range(1000):
        ring.add(line(f"{i:04d} " + "x" * 4000))
    assert ring.bytes <= 100_000
    assert len(ring) == 100_000 // (LINE_OVERHEAD_BYTES + 4005)
    assert ring.query(limit=1)[0]["msg"].startswith("0999 ")
    ring.add(line("y" * 500_000))  # a line over the whole budget (not cut): kept alone, the newest
    assert len(ring) == 1 and ring.query(limit=1)[0]["msg"][0] == "y"
    ring.add(line("short"))
    assert [x["msg"] for x in ring.query()] == ["short"]
    assert ring.bytes == LINE_OVERHEAD_BYTES + len("short") + len("talker")


def test_each_field_of_a_log_message_is_cut_on_arrival():
    from rcl_interfaces.msg import Log

    from rover_web.logs.msgs import MAX_MSG_CHARS, MAX_NAME_CHARS, log_line

    msg = Log(level=40, name="n" * 100_000, msg="m" * 1_000_000, file="f" * 100_000, function="g" * 100_000, line=7)
    cut = log_line(msg)
    assert cut["msg"].startswith("m" * MAX_MSG_CHARS + "… [996000 more characters cut]")
    for key in ("node", "file", "function"):
        assert len(cut[key]) < MAX_NAME_CHARS + 40 and cut[key].endswith("more characters cut]")
    assert line_bytes(cut) < 6000
    short = log_line(Log(level=20, name="talker", msg="hello", file="a.py", function="main", line=1))
    assert (short["node"], short["msg"], short["file"], short["function"]) == ("talker", "hello", "a.py", "main")
