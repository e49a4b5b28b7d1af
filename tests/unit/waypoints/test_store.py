"""The mission store on a real SQLite file: order, limits, atomicity and the schema's own checks."""

import math
import sqlite3

import pytest

from rover_web.storage.db import Database
from rover_web.waypoints.store import (
    MissionFull,
    StaleRevision,
    WaypointNotFound,
    WaypointStore,
    check_label,
    check_lat,
    check_lng,
)
from rover_web.web.validate import InvalidInput


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "rover.sqlite3")
    yield database
    database.close()


@pytest.fixture
def store(db):
    store = WaypointStore(db, max_waypoints=5)
    yield store
    store.close()


def positions_are_contiguous(db) -> bool:
    rows = [r[0] for r in db.connection().execute("SELECT position FROM waypoints ORDER BY position")]
    return rows == list(range(len(rows)))


def coords(store):
    return [(w.lng, w.lat) for w in store.mission().waypoints]


def test_add_appends_in_order_and_bumps_the_revision(store, db):
    first, r1 = store.add(1.0, 2.0)
    second, r2 = store.add(3.0, 4.0, "buoy")
    assert (first.index, second.index) == (0, 1)
    assert r2 == r1 + 1
    mission = store.mission()
    assert mission.revision == r2
    assert [w.to_dict() for w in mission.waypoints] == [
        {"id": first.id, "index": 0, "lng": 1.0, "lat": 2.0, "label": ""},
        {"id": second.id, "index": 1, "lng": 3.0, "lat": 4.0, "label": "buoy"}]


def test_the_maximum_is_enforced_and_nothing_is_written_beyond_it(store):
    for i in range(5):
        store.add(float(i), 0.0)
    revision = store.mission().revision
    with pytest.raises(MissionFull):
        store.add(9.0, 9.0)
    assert len(store.mission().waypoints) == 5 and store.mission().revision == revision


def test_move_rename_and_reorder(store, db):
    ids = [store.add(float(i), float(i))[0].id for i in range(4)]
    moved, _ = store.update(ids[1], lng=10.5, lat=-20.25)
    assert (moved.lng, moved.lat, moved.index) == (10.5, -20.25, 1)
    renamed, _ = store.update(ids[1], label="gate")
    assert renamed.label == "gate" and renamed.lng == 10.5
    store.update(ids[3], index=0)
    assert [w.id for w in store.mission().waypoints] == [ids[3], ids[0], ids[1], ids[2]]
    store.update(ids[3], index=99)  # past the end: clamped to last
    assert [w.id for w in store.mission().waypoints] == [ids[0], ids[1], ids[2], ids[3]]
    assert positions_are_contiguous(db)


def test_delete_closes_the_gap_and_clear_empties(store, db):
    ids = [store.add(float(i), 0.0)[0].id for i in range(5)]
    store.delete(ids[2])
    assert [w.id for w in store.mission().waypoints] == [ids[0], ids[1], ids[3], ids[4]]
    assert [w.index for w in store.mission().waypoints] == [0, 1, 2, 3]
    assert positions_are_contiguous(db)
    with pytest.raises(WaypointNotFound):
        store.delete(ids[2])
    with pytest.raises(WaypointNotFound):
        store.update(ids[2], lng=1.0)
    assert store.clear()[0] == 4
    assert store.mission().waypoints == ()
    store.add(1.0, 1.0)
    assert store.mission().waypoints[0].index == 0


def test_replace_is_all_or_nothing(store, db):
    store.add(1.0, 1.0)
    mission = store.replace([(5.0, 6.0, "a"), (7.0, 8.0, "b")])
    assert [(w.lng, w.lat, w.label) for w in mission.waypoints] == [(5.0, 6.0, "a"), (7.0, 8.0, "b")]
    before = store.mission()
    with pytest.raises(MissionFull):
        store.replace([(0.0, 0.0, "")] * 6)
    with pytest.raises(StaleRevision):
        store.replace([(0.0, 0.0, "")], expected_revision=before.revision - 1)
    # A row the schema refuses half way through rolls the whole import back.
    with pytest.raises(sqlite3.IntegrityError):
        store.replace([(1.0, 1.0, ""), (1.0, 95.0, "")])
    assert store.mission() == before


@pytest.mark.parametrize("column, value", [
    ("lat", 90.5), ("lat", -91.0), ("lng", 180.001), ("lng", -200.0), ("lat", math.nan), ("lng", math.inf),
    ("lng", "east"), ("lat", None),
])
def test_the_schema_itself_refuses_impossible_waypoints(db, store, column, value):
    """Even code that skips validation cannot store a waypoint the robot must not receive."""
    row = {"position": 0, "lng": 1.0, "lat": 2.0, "label": "", "created_at": 1.0, column: value}
    with pytest.raises(sqlite3.IntegrityError):
        with db.transaction() as conn:
            conn.execute("INSERT INTO waypoints (position, lng, lat, label, created_at) "
                         "VALUES (:position, :lng, :lat, :label, :created_at)", row)
    assert store.mission().waypoints == ()


def test_the_schema_refuses_duplicate_or_negative_positions_and_long_labels(db, store):
    store.add(1.0, 1.0)
    for position, label in [(0, ""), (-1, ""), (1, "x" * 81)]:
        with pytest.raises(sqlite3.IntegrityError):
            with db.transaction() as conn:
                conn.execute("INSERT INTO waypoints (position, lng, lat, label, created_at) VALUES (?, 1, 1, ?, 1)",
                             (position, label))
    assert len(store.mission().waypoints) == 1


def test_the_mission_survives_reopening_the_file(tmp_path):
    path = tmp_path / "again.sqlite3"
    first = Database(path)
    store = WaypointStore(first, 10)
    store.add(-82.45, 27.37, "dock")
    store.close()
    first.close()
    second = Database(path)
    store = WaypointStore(second, 10)
    try:
        mission = store.mission()  # ensure_schema again: nothing is reset
        assert [(w.lng, w.lat, w.label) for w in mission.waypoints] == [(-82.45, 27.37, "dock")]
        assert mission.revision == 1
    finally:
        store.close()
        second.close()


@pytest.mark.parametrize("value, code", [
    (None, "bad_type"), ("1.0", "bad_type"), (True, "bad_type"), ([1], "bad_type"), (math.nan, "non_finite"),
    (math.inf, "non_finite"), (180.0001, "out_of_range"), (-180.5, "out_of_range"), (10 ** 400, "out_of_range"),
])
def test_check_lng_refuses(value, code):
    with pytest.raises(InvalidInput) as err:
        check_lng(value)
    assert err.value.code == code


def test_coordinate_and_label_rules():
    assert check_lng(-180) == -180.0 and check_lng(180) == 180.0
    assert check_lat(90) == 90.0 and check_lat(-90.0) == -90.0
    with pytest.raises(InvalidInput):
        check_lat(90.000001)
    assert check_label(None) == "" and check_label("Gate 1 ⛵") == "Gate 1 ⛵"
    for bad in ["x" * 81, "line\nbreak", "\x00", "\ud800", 5]:
        with pytest.raises(InvalidInput):
            check_label(bad)
