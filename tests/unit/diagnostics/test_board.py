"""Diagnostics board: latest per name, ages on the monotonic clock, stale after a while, worst per hardware."""

from rover_web.diagnostics.board import ERROR, OK, STALE, WARN, DiagnosticsBoard


def status(name, level=OK, hardware_id="hw", message="ok"):
    return {"name": name, "hardware_id": hardware_id, "level": level, "message": message, "values": {"k": "v"}}


def test_the_latest_status_per_name_with_its_age_turns_stale():
    now = [100.0]
    board = DiagnosticsBoard(stale_s=2.0, clock=lambda: now[0])
    board.update([status("battery", WARN, "bat"), status("gps", OK, "gps")], "/diagnostics")
    now[0] += 1.5
    board.update([status("gps", ERROR, "gps", "lost")], "/diagnostics")
    snap = {s["name"]: s for s in board.snapshot()}
    assert snap["battery"]["age_s"] == 1.5 and not snap["battery"]["stale"]
    assert snap["gps"]["level"] == ERROR and snap["gps"]["message"] == "lost" and snap["gps"]["age_s"] == 0
    assert snap["gps"]["source"] == "/diagnostics" and snap["gps"]["values"] == {"k": "v"}
    now[0] += 1.0
    snap = {s["name"]: s for s in board.snapshot()}
    assert snap["battery"]["stale"] and not snap["gps"]["stale"]
    assert snap["battery"]["level"] == WARN  # the last level is kept; stale is said beside it


def test_worst_level_per_hardware_id_with_stale_worst_of_all():
    now = [0.0]
    board = DiagnosticsBoard(stale_s=5.0, clock=lambda: now[0])
    board.update([status("left", OK, "motors"), status("right", WARN, "motors"), status("bat", OK, "battery")], "x")
    rows = {r["hardware_id"]: r for r in board.worst_by_hardware(board.snapshot())}
    assert rows["motors"]["level"] == WARN and rows["motors"]["names"] == ["left", "right"]
    assert rows["battery"]["level_name"] == "OK"
    now[0] = 10.0
    board.update([status("left", ERROR, "motors")], "x")
    rows = board.worst_by_hardware(board.snapshot())
    assert [(r["hardware_id"], r["level"]) for r in rows] == [("battery", STALE), ("motors", STALE)]


def test_names_are_bounded():
    board = DiagnosticsBoard(stale_s=5.0, max_names=3)
    board.update([status(f"n{i}") for i in range(10)], "x")
    assert len(board) == 3
