"""Sessions that end (issue 27): server-side sessions checked on every request, sign-out that a
copied cookie does not survive, sign out everywhere, hours not days, a long signing key; and with
sign-in off, no users and tokens API, and sign-in for requests that came from beyond this machine."""

import logging
import sqlite3
from datetime import timedelta

import pytest

from rover_web.config import ConfigError
from tests.support.auth import add_users, sign_in


def copy_of_cookie(client, app):
    """A second client holding the same session cookie, as a thief (or a second tab) would."""
    other = app.test_client()
    other.set_cookie("session", client.get_cookie("session").value)
    return other


def admin_headers(app):
    return {"Authorization": f"Bearer {app.tokens['admin']}"}


def test_a_copy_of_the_cookie_is_refused_after_sign_out(signed_app):
    client = signed_app.test_client()
    sign_in(client, "operator")
    stolen = copy_of_cookie(client, signed_app)
    assert stolen.get("/api/me").get_json()["user"] == "operator"
    assert client.post("/logout", json={}).get_json() == {"signed_out": True}
    assert stolen.get("/api/me").status_code == 401
    assert client.get("/api/me").status_code == 401


def test_a_password_change_ends_the_user_s_sessions_but_not_the_admin_s_own(signed_app):
    client = signed_app.test_client()
    sign_in(client, "operator")
    admin = signed_app.test_client()
    sign_in(admin, "admin")
    assert admin.patch("/api/users/operator", json={"password": "a new password"}).status_code == 200
    assert client.get("/api/me").status_code == 401
    assert sign_in(client, "operator").status_code == 401  # the old password is gone too
    assert sign_in(client, "operator", "a new password").status_code == 303
    # An admin changing their own password stays signed in in that browser, and only there.
    other_admin_browser = copy_of_cookie(admin, signed_app)
    changed = admin.patch("/api/users/admin", json={"password": "another password"})
    assert changed.status_code == 200
    assert admin.get("/api/me").get_json()["user"] == "admin"
    assert other_admin_browser.get("/api/me").status_code == 401


def test_a_user_made_again_under_the_same_name_is_not_reached_by_an_old_cookie(signed_app):
    old_viewer = signed_app.test_client()
    sign_in(old_viewer, "viewer")
    admin = signed_app.test_client()
    headers = admin_headers(signed_app)
    assert admin.delete("/api/users/viewer", headers=headers).status_code == 200
    made = admin.post("/api/users", json={"name": "viewer", "role": "admin", "password": "long enough"},
                      headers=headers)
    assert made.status_code == 201
    assert old_viewer.get("/api/me").status_code == 401
    assert old_viewer.get("/api/users").status_code == 401


def test_sign_out_everywhere_ends_every_session_of_the_caller_only(signed_app):
    laptop, phone, someone_else = (signed_app.test_client() for _ in range(3))
    sign_in(laptop, "operator")
    sign_in(phone, "operator")
    sign_in(someone_else, "viewer")
    answer = phone.post("/api/me/sessions/revoke", json={})
    assert answer.status_code == 200
    assert answer.get_json()["user"] == "operator" and answer.get_json()["signed_out_everywhere"] is True
    assert laptop.get("/api/me").status_code == 401 and phone.get("/api/me").status_code == 401
    assert someone_else.get("/api/me").get_json()["user"] == "viewer"
    token = {"Authorization": f"Bearer {signed_app.tokens['operator']}"}
    assert laptop.get("/api/me", headers=token).get_json()["user"] == "operator"  # tokens stay valid
    assert laptop.post("/api/me/sessions/revoke", json={}).status_code == 401  # not signed in


def test_a_session_ends_after_its_hours_whatever_the_cookie_says(signed_app):
    assert signed_app.permanent_session_lifetime == timedelta(hours=12)  # not Flask's 31 days
    client = signed_app.test_client()
    sign_in(client, "viewer")
    assert client.get("/api/me").status_code == 200
    conn = sqlite3.connect(signed_app.config["ROVER_WEB_DB_PATH"])
    try:
        lasts = conn.execute("SELECT expires_at - created_at FROM auth_sessions").fetchone()[0]
        assert lasts == pytest.approx(12 * 3600)
        with conn:
            conn.execute("UPDATE auth_sessions SET expires_at = created_at - 1")  # 12 h later
    finally:
        conn.close()
    assert client.get("/api/me").status_code == 401


def test_the_session_hours_are_a_setting(app_factory, tmp_path):
    db_path = tmp_path / "hours.sqlite3"
    add_users(db_path, "viewer")
    app = app_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path), ROVER_WEB_SESSION_HOURS=2)
    client = app.test_client()
    sign_in(client, "viewer")
    conn = sqlite3.connect(db_path)
    try:
        assert conn.execute("SELECT expires_at - created_at FROM auth_sessions").fetchone()[0] == pytest.approx(7200)
    finally:
        conn.close()
    assert app.permanent_session_lifetime == timedelta(hours=2)


def test_the_cookie_holds_no_user_name(signed_app):
    client = signed_app.test_client()
    sign_in(client, "operator")
    serializer = signed_app.session_interface.get_signing_serializer(signed_app)
    data = serializer.loads(client.get_cookie("session").value)
    assert "operator" not in str(data.values()) and len(data["_user_id"]) >= 40


@pytest.mark.parametrize("key", ["tests", "x" * 31, "ü" * 15])
def test_a_signing_key_under_32_bytes_is_refused_at_start(app_factory, key):
    with pytest.raises(ConfigError, match=r"ROVER_WEB_SECRET_KEY is \d+ bytes"):
        app_factory(ROVER_WEB_SECRET_KEY=key)


def test_a_short_key_file_is_refused_too(app_factory, tmp_path):
    instance = tmp_path / "instance"
    instance.mkdir()
    (instance / "secret_key").write_text("short\n")
    from rover_web.auth.service import secret_key

    with pytest.raises(ConfigError, match="secret_key is 5 bytes"):
        secret_key(None, str(instance))


# --- with sign-in off ---

def test_with_sign_in_off_the_users_and_tokens_api_is_refused_and_changes_nothing(app_factory, tmp_path):
    db_path = tmp_path / "off.sqlite3"
    add_users(db_path, "viewer")
    for mode in ("auto", "off"):  # auto on loopback, and off
        app = app_factory(ROVER_WEB_AUTH=mode, ROVER_WEB_DB_PATH=str(db_path))
        client = app.test_client()
        calls = [("GET", "/api/users", None), ("POST", "/api/users", {"name": "eve", "role": "admin",
                                                                      "password": "long enough"}),
                 ("PATCH", "/api/users/viewer", {"role": "admin"}), ("DELETE", "/api/users/viewer", None),
                 ("GET", "/api/tokens", None), ("POST", "/api/tokens", {"user": "viewer"}),
                 ("DELETE", "/api/tokens/1", None)]
        for method, path, body in calls:
            answer = client.open(path, method=method, json=body)
            assert answer.status_code == 403, (mode, method, path)
            assert answer.get_json()["error"] == "sign_in_off" and "flask --app rover_web users" in \
                answer.get_json()["message"]
        assert client.get("/api/status").status_code == 200  # the rest is open, as before
        app.extensions["rover_web"].shutdown()  # one server per database: free it for the next
    conn = sqlite3.connect(db_path)
    try:
        assert conn.execute("SELECT name, role FROM auth_users").fetchall() == [("viewer", "viewer")]
        assert conn.execute("SELECT count(*) FROM auth_tokens WHERE revoked_at IS NULL").fetchone()[0] == 1
    finally:
        conn.close()


@pytest.fixture
def loopback_app_with_users(app_factory, tmp_path):
    db_path = tmp_path / "auto.sqlite3"
    tokens = add_users(db_path)
    app = app_factory(ROVER_WEB_AUTH="auto", ROVER_WEB_DB_PATH=str(db_path),
                      ROVER_WEB_TRUSTED_HOSTS=["127.0.0.1", "localhost", "robot.example"])
    app.tokens = tokens
    return app


@pytest.mark.parametrize("header", ["X-Forwarded-For", "X-Forwarded-Host", "X-Forwarded-Proto", "Forwarded"])
def test_under_auto_a_request_through_a_proxy_must_sign_in(loopback_app_with_users, header):
    client = loopback_app_with_users.test_client()
    proxied = {header: "for=203.0.113.7" if header == "Forwarded" else "203.0.113.7"}
    assert client.get("/api/me").get_json()["sign_in"] is False  # made on this machine: sign-in off
    assert client.get("/api/status", headers=proxied).status_code == 401
    assert client.post("/api/teleop", json={"command": "stop"}, headers=proxied).status_code == 401
    page = client.get("/", headers=proxied)
    assert page.status_code == 302 and page.headers["Location"].startswith("/login")
    assert sign_in(client, "operator").status_code == 303
    me = client.get("/api/me", headers=proxied).get_json()
    assert me["user"] == "operator" and me["sign_in"] is True
    assert client.get("/api/users", headers=proxied).status_code == 403  # an operator, not an admin
    admin = {"Authorization": f"Bearer {loopback_app_with_users.tokens['admin']}", **proxied}
    assert client.get("/api/users", headers=admin).status_code == 200


def test_under_auto_a_request_for_a_name_other_than_loopback_must_sign_in(loopback_app_with_users, caplog):
    client = loopback_app_with_users.test_client()
    answer = client.get("/api/status", headers={"Host": "robot.example"})
    assert answer.status_code == 401
    assert client.get("/api/status", headers={"Host": "localhost:5000"}).status_code == 200


def test_under_auto_the_start_warns_what_is_open_and_what_is_not(app_factory, caplog):
    with caplog.at_level(logging.WARNING):
        app_factory(ROVER_WEB_TRUSTED_HOSTS=["127.0.0.1", "robot.example"])
    assert "sign-in is off for requests made on this machine" in caplog.text
    assert "X-Forwarded-*" in caplog.text and "robot.example" in caplog.text


def test_under_auto_with_no_user_a_proxied_request_is_refused_with_what_to_do(client):
    answer = client.get("/api/status", headers={"X-Forwarded-For": "203.0.113.7"})
    assert answer.status_code == 403
    assert answer.get_json()["error"] == "sign_in_needed"
    assert "ROVER_WEB_AUTH=required" in answer.get_json()["message"]
    assert client.get("/api/status").status_code == 200


def test_sign_out_everywhere_with_sign_in_off_is_a_409(client):
    answer = client.post("/api/me/sessions/revoke", json={})
    assert answer.status_code == 409 and answer.get_json()["error"] == "sign_in_off"



def test_under_auto_a_proxied_operator_is_told_ros_writes_are_admin_work(loopback_app_with_users):
    """The pages decide what to offer from the request's own sign-in rule, not the server's: under
    `auto` a proxied request must sign in, so an operator there is an operator, not everyone."""
    client = loopback_app_with_users.test_client()
    proxied = {"X-Forwarded-For": "203.0.113.7"}
    assert sign_in(client, "operator").status_code == 303
    page = client.get("/ros", headers=proxied).get_data(as_text=True)
    assert "needs the admin role" in page and 'data-can-cancel="yes"' in page
    local = client.get("/ros").get_data(as_text=True)  # made on this machine: sign-in off, anyone may
    assert "needs the admin role" not in local
