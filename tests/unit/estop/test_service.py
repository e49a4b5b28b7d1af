"""The e-stop latch: what engaging and releasing do, in order, with a real SQLite store."""

import threading

import pytest

from rover_web.estop.service import EStopEngaged, EStopService, ReleaseRefused
from rover_web.estop.store import EStopStore
from rover_web.storage.db import Database


class Robot:
    """Records what the e-stop did, in order."""

    def __init__(self):
        self.events = []
        self.changes = []

    def zero(self):
        self.events.append("zero")

    def hold(self):
        self.events.append("hold")

    def unhold(self):
        self.events.append("unhold")

    def flag(self, engaged):
        self.events.append(f"flag:{engaged}")


class BlockingStore(EStopStore):
    """A store whose next release write waits until the test lets it go."""

    def __init__(self, db):
        super().__init__(db)
        self.release_started = threading.Event()
        self.let_go = threading.Event()
        self.fail_next = False

    def save(self, state):
        if self.fail_next:
            self.fail_next = False
            raise OSError("disk full")
        if not state["engaged"] and not self.let_go.is_set():
            self.release_started.set()
            assert self.let_go.wait(5)
        super().save(state)


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "estop.sqlite3")
    yield database
    database.close()


class Canceller:
    def __init__(self):
        self.asked = []

    def cancel_all(self, on_done):
        self.asked.append(on_done)

    def running(self):
        return ["/navigate_to_pose"]


def make(db, robot, store=None, canceller=None):
    store = store or EStopStore(db)
    return EStopService(store, zero=robot.zero, publish_flag=robot.flag, canceller=canceller,
                        on_change=robot.changes.append)


def test_engage_stops_first_then_says_so_on_ros_then_hooks_then_records(db):
    robot = Robot()
    estop = make(db, robot)
    estop.on_engage(lambda by: robot.events.append(f"hook:{by}"))
    state = estop.engage("ada", via="api")
    assert robot.events == ["zero", "flag:True", "hook:ada"]
    assert state["engaged"] and state["by"] == "ada" and state["via"] == "api" and state["persisted"] is True
    assert EStopStore(db).load()["engaged"] is True
    assert robot.changes[-1]["engaged"]


def test_engage_twice_stops_again_but_keeps_the_first_engage(db):
    robot = Robot()
    estop = make(db, robot)
    first = estop.engage("ada")
    again = estop.engage("bob")
    assert again["since"] == first["since"] and again["by"] == "ada"
    assert robot.events.count("zero") == 2


def test_motion_is_refused_while_engaged_and_allowed_after_release(db):
    robot = Robot()
    estop = make(db, robot)
    estop.check_motion()
    estop.engage("ada")
    with pytest.raises(EStopEngaged, match="engaged by ada"):
        estop.check_motion()
    released = []
    estop.on_release(released.append)
    state = estop.release("bob")
    assert not state["engaged"] and state["by"] == "bob" and released == ["bob"]
    assert robot.events[-1] == "flag:False"
    estop.check_motion()
    assert EStopStore(db).load()["engaged"] is False


def test_zero_keeps_going_out_only_while_engaged(db):
    robot = Robot()
    estop = make(db, robot)
    estop.hold()
    assert robot.events == []
    estop.engage("ada")
    robot.events.clear()
    estop.hold(), estop.hold()
    assert robot.events == ["zero", "zero"]


def test_republish_repeats_the_current_flag(db):
    robot = Robot()
    estop = make(db, robot)
    estop.republish()
    estop.engage("ada")
    estop.republish()
    assert robot.events[0] == "flag:False" and robot.events[-1] == "flag:True"


def test_the_latch_survives_a_restart(db):
    make(db, Robot()).engage("ada")
    again = make(db, Robot())
    assert again.engaged and again.state()["by"] == "ada"
    with pytest.raises(EStopEngaged):
        again.check_motion()


def test_engaging_never_waits_behind_a_release_being_written(db):
    robot = Robot()
    store = BlockingStore(db)
    estop = make(db, robot, store)
    estop.engage("ada")
    outcome = {}

    def release():
        try:
            estop.release("bob")
        except ReleaseRefused as exc:
            outcome["refused"] = exc

    releaser = threading.Thread(target=release)
    releaser.start()
    assert store.release_started.wait(5)  # the release is now inside its database write
    robot.events.clear()
    engaged = threading.Thread(target=estop.engage, args=("cyd",))
    engaged.start()
    engaged.join(2)
    assert not engaged.is_alive() and robot.events[0] == "zero"  # stopped while the write was blocked
    store.let_go.set()
    releaser.join(5)
    assert outcome["refused"].code == "estop_engaged"  # the release is abandoned
    assert estop.engaged
    assert EStopStore(db).load()["engaged"] is True  # and the disk does not keep it either


def test_a_release_that_cannot_be_recorded_leaves_the_e_stop_engaged(db):
    robot = Robot()
    store = BlockingStore(db)
    store.let_go.set()
    estop = make(db, robot, store)
    estop.engage("ada")
    store.fail_next = True
    with pytest.raises(ReleaseRefused) as exc:
        estop.release("bob")
    assert exc.value.status == 503 and estop.engaged


def test_an_engage_that_cannot_be_recorded_still_stops_and_says_so(db):
    robot = Robot()
    store = BlockingStore(db)
    store.fail_next = True
    estop = make(db, robot, store)
    state = estop.engage("ada")
    assert estop.engaged and robot.events[0] == "zero"
    assert state["persisted"] is False


def test_a_failing_hook_does_not_keep_the_others_or_the_flag_from_running(db):
    robot = Robot()
    estop = make(db, robot)
    estop.on_engage(lambda by: 1 / 0)
    estop.on_engage(lambda by: robot.events.append("second hook"))
    estop.engage("ada")
    assert robot.events == ["zero", "flag:True", "second hook"]


def test_goal_cancel_outcomes_join_the_state(db):
    robot = Robot()
    canceller = Canceller()
    estop = make(db, robot, canceller=canceller)
    assert estop.cancellable_actions() == ["/navigate_to_pose"]
    estop.engage("ada")
    estop.engage("ada")  # already engaged: not asked twice
    assert len(canceller.asked) == 1
    canceller.asked[0]([{"action": "/navigate_to_pose", "result": "canceled", "goals": 1}])
    assert estop.state()["cancel"] == [{"action": "/navigate_to_pose", "result": "canceled", "goals": 1}]
    assert robot.changes[-1]["cancel"][0]["result"] == "canceled"


def test_the_output_is_held_from_the_engage_to_the_release_and_at_start_while_engaged(db):
    robot = Robot()
    estop = EStopService(EStopStore(db), zero=robot.zero, publish_flag=robot.flag, on_change=robot.changes.append,
                         hold=robot.hold, unhold=robot.unhold)
    estop.engage("ada")
    estop.hold()  # the 40 Hz loop only sends zero: it never re-holds behind a release
    assert robot.events == ["hold", "flag:True", "zero"]
    estop.release("ada")
    assert robot.events[3:] == ["unhold", "flag:False"]
    estop.engage("bob")
    restarted = Robot()
    EStopService(EStopStore(db), zero=restarted.zero, publish_flag=restarted.flag,
                 on_change=restarted.changes.append, hold=restarted.hold, unhold=restarted.unhold)
    assert restarted.events == ["hold"]  # engaged since the last run: held before anything drives
