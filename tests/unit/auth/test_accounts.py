"""Users, roles and API tokens in a real SQLite database."""

import sqlite3

import pytest
from argon2 import PasswordHasher

from rover_web.auth.accounts import AccountError, Accounts, User, password_hasher, token_digest
from rover_web.auth.throttle import HashGate, HashingBusy
from rover_web.storage.db import Database


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "auth.sqlite3")
    yield database
    database.close()


@pytest.fixture
def accounts(db):
    made = Accounts(db)
    yield made
    made.gate.close()


def test_a_user_signs_in_with_their_password_only(accounts):
    accounts.add_user("ada", "operator", "correct horse")
    assert accounts.authenticate("ada", "correct horse") == User("ada", "operator")
    assert accounts.authenticate("ada", "wrong horse!") is None
    assert accounts.authenticate("bob", "correct horse") is None
    assert accounts.authenticate("ada", "x" * 5000) is None


def test_the_password_is_stored_as_an_argon2id_hash_never_in_clear(accounts, db):
    accounts.add_user("ada", "viewer", "correct horse")
    stored = db.connection().execute("SELECT password_hash FROM auth_users").fetchone()[0]
    assert stored.startswith("$argon2id$")
    assert "correct horse" not in stored


@pytest.mark.parametrize("name,role,password,code", [
    ("", "viewer", "long enough", "bad_name"),
    ("a b", "viewer", "long enough", "bad_name"),
    ("x" * 41, "viewer", "long enough", "bad_name"),
    ("ada\n", "viewer", "long enough", "bad_name"),
    ("ada", "root", "long enough", "bad_role"),
    ("ada", "viewer", "short", "bad_password"),
])
def test_bad_accounts_are_refused_and_nothing_is_stored(accounts, name, role, password, code):
    with pytest.raises(AccountError) as exc:
        accounts.add_user(name, role, password)
    assert exc.value.code == code
    assert accounts.count() == 0


def test_a_name_is_taken_once(accounts):
    accounts.add_user("ada", "viewer", "long enough")
    with pytest.raises(AccountError) as exc:
        accounts.add_user("ada", "admin", "other password")
    assert exc.value.code == "user_exists"
    assert accounts.get("ada").role == "viewer"


def test_roles_include_the_ones_below():
    assert User("a", "admin").may("operator") and User("a", "admin").may("viewer")
    assert User("o", "operator").may("viewer") and not User("o", "operator").may("admin")
    assert not User("v", "viewer").may("operator")


def test_set_role_and_remove(accounts):
    accounts.add_user("ada", "viewer", "long enough")
    accounts.set_role("ada", "admin")
    assert accounts.get("ada") == User("ada", "admin")
    with pytest.raises(AccountError):
        accounts.set_role("nobody", "admin")
    accounts.remove_user("ada")
    assert accounts.get("ada") is None
    with pytest.raises(AccountError):
        accounts.remove_user("ada")


def test_a_token_acts_as_its_user_until_revoked_and_only_its_hash_is_stored(accounts, db):
    accounts.add_user("ada", "operator", "long enough")
    token_id, token = accounts.create_token("ada", "script")
    assert accounts.user_for_token(token) == User("ada", "operator")
    stored = db.connection().execute("SELECT token_sha256 FROM auth_tokens").fetchone()[0]
    assert stored == token_digest(token) and token not in stored
    assert accounts.user_for_token(token + "x") is None
    assert accounts.user_for_token("not-a-token") is None
    accounts.revoke_token(token_id)
    assert accounts.user_for_token(token) is None
    assert accounts.tokens()[0]["revoked_at"] is not None


def test_a_token_follows_its_users_role_and_dies_with_the_user(accounts):
    accounts.add_user("ada", "operator", "long enough")
    _, token = accounts.create_token("ada")
    accounts.set_role("ada", "viewer")
    assert accounts.user_for_token(token).role == "viewer"
    accounts.remove_user("ada")
    assert accounts.user_for_token(token) is None
    assert accounts.tokens() == []


def test_a_token_for_nobody_is_refused(accounts):
    with pytest.raises(AccountError) as exc:
        accounts.create_token("ghost")
    assert exc.value.code == "no_such_user"
    assert accounts.tokens() == []


def test_the_schema_refuses_a_role_the_code_does_not_know(accounts, db):
    with pytest.raises(sqlite3.IntegrityError):
        with db.transaction() as conn:
            conn.execute("INSERT INTO auth_users VALUES ('eve', 'root', 'x', 0)")


def test_revoking_a_token_id_beyond_sqlite_integers_is_no_such_token_not_an_overflow(accounts):
    """Found by the fuzz (docs/api.md): DELETE /api/tokens/<26 digits> was a 500 (OverflowError)."""
    for token_id in (1 << 63, 10**25):
        with pytest.raises(AccountError) as refused:
            accounts.revoke_token(token_id)
        assert refused.value.code == "no_such_token"


def test_new_hashes_use_owasps_small_computer_parameters(accounts, db):
    accounts.add_user("ada", "viewer", "correct horse")
    stored = db.connection().execute("SELECT password_hash FROM auth_users").fetchone()[0]
    assert "$m=19456,t=2,p=1$" in stored


def test_a_hash_with_the_old_parameters_still_verifies_and_is_replaced_at_sign_in(db):
    old = Accounts(db, PasswordHasher(time_cost=3, memory_cost=65536, parallelism=4))  # argon2-cffi's default
    old.add_user("ada", "operator", "correct horse")
    accounts = Accounts(db, password_hasher(12288, 3))
    assert accounts.authenticate("ada", "wrong horse!") is None
    assert "$m=65536,t=3,p=4$" in _stored(db)  # a wrong password changes nothing
    assert accounts.authenticate("ada", "correct horse") == User("ada", "operator")
    assert "$m=12288,t=3,p=1$" in _stored(db)
    assert accounts.authenticate("ada", "correct horse") == User("ada", "operator")
    old.gate.close(), accounts.gate.close()


def test_a_sign_in_with_every_hashing_slot_taken_is_refused_before_any_hash(db):
    accounts = Accounts(db, gate=HashGate(1))
    accounts.add_user("ada", "operator", "correct horse")
    hashed = accounts.gate.hashed
    with accounts.gate.slot():
        with pytest.raises(HashingBusy):
            accounts.authenticate("ada", "correct horse")
        with pytest.raises(HashingBusy):
            accounts.authenticate("nobody", "correct horse")  # the dummy hash takes a slot too
    assert accounts.gate.hashed == hashed + 1  # only the test's own slot
    assert accounts.authenticate("ada", "correct horse") == User("ada", "operator")
    accounts.gate.close()


def _stored(db) -> str:
    return db.connection().execute("SELECT password_hash FROM auth_users").fetchone()[0]
