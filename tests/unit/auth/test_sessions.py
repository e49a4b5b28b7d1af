"""Sessions and session epochs on a real SQLite file (rover_web/auth/sessions.py)."""

import pytest

from rover_web.auth.accounts import Accounts
from rover_web.auth.sessions import ENDED_EVERYWHERE, Sessions
from rover_web.storage.db import Database

PASSWORD = "correct horse battery"


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "auth.sqlite3")
    yield database
    database.close()


@pytest.fixture
def auth(db):
    accounts = Accounts(db)
    for role in ("viewer", "operator", "admin"):
        accounts.add_user(role, role, PASSWORD)
    return accounts, Sessions(db, 12 * 3600.0)


def test_a_session_holds_until_it_is_ended_and_then_its_id_means_nothing(auth):
    _accounts, sessions = auth
    session_id, credential = sessions.start("operator")
    assert sessions.for_session(session_id) == credential
    assert (credential.user, credential.role, credential.via) == ("operator", "operator", "session")
    other_id, _ = sessions.start("operator")
    sessions.end(session_id)
    assert sessions.for_session(session_id) is None
    assert sessions.ended(credential) == "signed out"
    assert sessions.for_session(other_id) is not None  # signing out ends this session only


def test_a_password_or_role_change_ends_every_session_even_from_another_connection(tmp_path, auth):
    _accounts, sessions = auth
    first, first_credential = sessions.start("operator")
    second, _ = sessions.start("viewer")
    other_process = Database(tmp_path / "auth.sqlite3")  # what `flask users set-password` does
    try:
        Accounts(other_process).set_password("operator", "a new password")
    finally:
        other_process.close()
    assert sessions.for_session(first) is None
    assert sessions.ended(first_credential) == ENDED_EVERYWHERE
    assert sessions.for_session(second) is not None
    _accounts.set_role("viewer", "operator")
    assert sessions.for_session(second) is None


def test_an_unchanged_role_written_again_keeps_sessions(auth):
    accounts, sessions = auth
    session_id, _ = sessions.start("operator")
    accounts.set_role("operator", "operator")
    assert sessions.for_session(session_id) is not None


def test_a_user_removed_and_made_again_under_the_same_name_does_not_inherit_old_sessions(auth):
    accounts, sessions = auth
    session_id, credential = sessions.start("viewer")
    accounts.remove_user("viewer")
    assert sessions.ended(credential) == "user removed"
    accounts.add_user("viewer", "admin", PASSWORD)
    assert sessions.for_session(session_id) is None
    assert sessions.ended(credential) is not None


def test_sign_out_everywhere_ends_sessions_and_token_streams_but_not_the_token(auth):
    accounts, sessions = auth
    _token_id, token = accounts.create_token("operator")
    token_credential = sessions.for_token(token)
    one, _ = sessions.start("operator")
    two, _ = sessions.start("operator")
    theirs, _ = sessions.start("admin")
    sessions.end_everywhere("operator")
    assert sessions.for_session(one) is None and sessions.for_session(two) is None
    assert sessions.for_session(theirs) is not None
    assert sessions.ended(token_credential) == ENDED_EVERYWHERE  # a stream opened with it closes
    assert sessions.ended(sessions.for_token(token)) is None  # the token itself still works


def test_a_revoked_token_has_ended(auth):
    accounts, sessions = auth
    token_id, token = accounts.create_token("viewer")
    credential = sessions.for_token(token)
    assert credential.key == str(token_id) and sessions.ended(credential) is None
    accounts.revoke_token(token_id)
    assert sessions.for_token(token) is None
    assert sessions.ended(credential) == "token revoked"
    assert sessions.for_token("rwt_made_up") is None and sessions.for_token("not a token") is None


def test_an_expired_session_is_refused(db, auth):
    _accounts, sessions = auth
    session_id, credential = sessions.start("viewer")
    with db.transaction() as conn:
        conn.execute("UPDATE auth_sessions SET expires_at = 0")
    assert sessions.for_session(session_id) is None
    assert sessions.ended(credential) == "session expired"


def test_a_session_lasts_the_configured_hours(db, auth):
    _accounts, _ = auth
    sessions = Sessions(db, 2 * 3600.0)
    sessions.start("viewer")
    row = db.connection().execute("SELECT expires_at - created_at AS lasts FROM auth_sessions").fetchone()
    assert row["lasts"] == pytest.approx(7200.0)


def test_users_made_before_the_session_tables_get_an_epoch(tmp_path):
    db = Database(tmp_path / "old.sqlite3")
    try:
        Accounts(db).add_user("old", "operator", PASSWORD)  # by the CLI, before any server ran
        sessions = Sessions(db, 3600.0)
        session_id, _ = sessions.start("old")
        assert sessions.for_session(session_id).user == "old"
    finally:
        db.close()


def test_only_a_digest_of_the_session_id_is_stored(db, auth):
    _accounts, sessions = auth
    session_id, _ = sessions.start("viewer")
    stored = [row[0] for row in db.connection().execute("SELECT id_sha256 FROM auth_sessions")]
    assert session_id not in stored and len(stored[0]) == 64
