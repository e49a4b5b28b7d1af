"""What a sign-in may cost and who may try again (issue 27): the bound on concurrent Argon2
hashes, attempts per address across names, back-off that cannot lock a user out from elsewhere,
and `next` that only ever goes to a path on this server."""

import threading
from urllib.parse import unquote

import pytest
import requests

from rover_web.auth.service import AuthService
from tests.support.auth import PASSWORD, add_users


@pytest.fixture
def signed(app_factory, tmp_path):
    """make(**settings): an app with sign-in required and one user per role."""
    db_path = tmp_path / "signed.sqlite3"
    add_users(db_path)

    def make(**settings):
        return app_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path), **settings)

    return make


def from_address(app, address):
    client = app.test_client()
    client.environ_base["REMOTE_ADDR"] = address
    return client


def test_parallel_sign_ins_beyond_the_hashing_bound_get_503_at_once_and_no_hash(live_server_factory, tmp_path):
    db_path = tmp_path / "signed.sqlite3"
    add_users(db_path)
    # 20 passes: each hash takes long enough that eight attempts started together overlap.
    server = live_server_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path),
                                 ROVER_WEB_SIGNIN_MAX_HASHING=2, ROVER_WEB_ARGON2_TIME_COST=20,
                                 ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN=100)
    gate = server.rover.feature(AuthService).accounts.gate
    hashed_before = gate.hashed
    start = threading.Barrier(8)
    answers = []

    def attempt(i):
        start.wait()
        # Unknown names: each is checked against the dummy hash, made with the configured 20 passes.
        answers.append(requests.post(f"{server.url}/login", json={"username": f"nobody{i}", "password": "guess guess"},
                                     timeout=60))

    threads = [threading.Thread(target=attempt, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    statuses = sorted(r.status_code for r in answers)
    busy = [r for r in answers if r.status_code == 503]
    assert set(statuses) <= {401, 503} and busy, statuses
    assert all(r.json()["error"] == "busy" and r.headers["Retry-After"] == "1" for r in busy)
    assert gate.peak <= 2
    assert gate.hashed - hashed_before == statuses.count(401)  # a 503 computed no hash
    assert gate.active == 0


def test_attempts_per_address_are_limited_across_names(signed):
    app = signed(ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN=3)
    a = from_address(app, "10.0.0.1")
    for name in ("viewer", "operator", "nobody"):
        assert a.post("/login", json={"username": name, "password": "guess guess"}).status_code == 401
    refused = a.post("/login", json={"username": "admin", "password": PASSWORD})
    assert refused.status_code == 429 and refused.get_json()["error"] == "too_many_attempts"
    assert 1 <= int(refused.headers["Retry-After"]) <= 60
    other = from_address(app, "10.0.0.2")
    assert other.post("/login", json={"username": "admin", "password": PASSWORD}).status_code == 200


def test_wrong_passwords_from_one_address_do_not_lock_out_the_user_from_another(signed):
    app = signed(ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN=100)
    attacker = from_address(app, "10.0.0.66")
    statuses = [attacker.post("/login", json={"username": "operator", "password": "guess guess"}).status_code
                for _ in range(8)]
    assert statuses[:5] == [401] * 5 and 429 in statuses  # the guesser backs off ...
    backed_off = attacker.post("/login", json={"username": "operator", "password": PASSWORD})
    assert backed_off.status_code == 429 and int(backed_off.headers["Retry-After"]) >= 1  # ... even with the password
    user = from_address(app, "10.0.0.7")
    signed_in = user.post("/login", json={"username": "operator", "password": PASSWORD})
    assert signed_in.status_code == 200  # ... not the user
    assert user.get("/api/me").get_json()["user"] == "operator"


def test_a_throttled_form_gets_the_form_back_with_429(signed):
    """Found by the fuzz (docs/api.md): the form's refusal was a tuple, and setting Retry-After on it raised."""
    app = signed(ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN=100)
    client = app.test_client()
    for _ in range(5):
        assert client.post("/login", data={"username": "operator", "password": "guess guess"}).status_code == 401
    locked = client.post("/login", data={"username": "operator", "password": PASSWORD})
    assert locked.status_code == 429 and int(locked.headers["Retry-After"]) >= 1
    assert locked.mimetype == "text/html" and b"too many failed sign-ins" in locked.data


OFF_SITE = [
    "/%09/evil.example",  # the issue's: a browser drops the tab and goes to //evil.example
    "/%0d%0aSet-Cookie:%20x=1",  # the issue's: a line break in Location was a 500
    "/%0a/evil.example",
    "//evil.example/",
    "///evil.example",
    "/%5Cevil.example",  # /\evil.example: a backslash reads as a slash
    "/%5C%5Cevil.example",
    "/%2F%2Fevil.example",  # decoded once more, //evil.example
    "%2F%2Fevil.example",
    "https://evil.example/",
    "javascript:alert(1)",
    "evil.example",
    "/%00",
    "/%7F",
    "",
]


@pytest.mark.parametrize("raw_next", OFF_SITE)
def test_next_that_is_not_a_local_path_goes_to_the_default_page(signed, raw_next):
    app = signed()
    client = app.test_client()
    form = client.get(f"/login?next={raw_next}")
    assert form.status_code == 200 and b'name="next" value="/"' in form.data
    assert client.post("/login", json={"username": "viewer", "password": PASSWORD}).status_code == 200
    signed_in = client.get(f"/login?next={raw_next}")
    assert signed_in.status_code == 302 and signed_in.headers["Location"] == "/"
    client.post("/logout")
    posted = client.post("/login", data={"username": "viewer", "password": PASSWORD, "next": unquote(raw_next)})
    assert posted.status_code == 303 and posted.headers["Location"] == "/"


@pytest.mark.parametrize("local", ["/livemap", "/api/status?x=1&y=2", "/robots/drone/", "/a%20b"])
def test_next_that_is_a_local_path_is_kept(signed, local):
    client = signed().test_client()
    posted = client.post("/login", data={"username": "viewer", "password": PASSWORD, "next": local})
    assert posted.status_code == 303 and posted.headers["Location"] == local
