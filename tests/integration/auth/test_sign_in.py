"""Sign-in with ROVER_WEB_AUTH: sessions, tokens, throttling, and when the app refuses to start."""

import pytest

from rover_web.auth.service import secret_key
from rover_web.config import ConfigError
from tests.support.auth import PASSWORD, sign_in


def test_auto_on_loopback_needs_no_sign_in(client):
    assert client.get("/api/me").get_json() == {"user": None, "role": "admin", "sign_in": False, "via": None}
    assert client.post("/api/teleop", json={"command": "stop"}).status_code == 200


def test_exposed_with_no_user_the_app_refuses_to_start(app_factory):
    with pytest.raises(ConfigError, match="users add NAME --role admin"):
        app_factory(ROVER_WEB_HOST="0.0.0.0")  # auto: not loopback, so sign-in is required
    with pytest.raises(ConfigError, match="no user exists"):
        app_factory(ROVER_WEB_AUTH="required")


def test_auth_off_serves_everyone_even_exposed(app_factory, caplog):
    app = app_factory(ROVER_WEB_AUTH="off", ROVER_WEB_HOST="0.0.0.0")
    assert app.test_client().post("/api/teleop", json={"command": "stop"}).status_code == 200
    assert "ROVER_WEB_AUTH=off" in caplog.text


def test_without_credentials_apis_answer_401_and_pages_redirect_to_the_form(signed_app):
    client = signed_app.test_client()
    response = client.get("/api/status")
    assert response.status_code == 401
    assert response.get_json()["error"] == "unauthenticated"
    assert response.headers["WWW-Authenticate"].startswith("Bearer")
    page = client.get("/livemap")
    assert page.status_code == 302 and page.headers["Location"].startswith("/login?next=/livemap")
    assert client.get("/login").status_code == 200
    with client.get("/static/css/app.css") as static_file:
        assert static_file.status_code == 200


def test_sign_in_sets_a_strict_http_only_cookie_and_sign_out_ends_it(signed_app):
    client = signed_app.test_client()
    response = sign_in(client, "operator")
    assert response.status_code == 303 and response.headers["Location"] == "/"
    cookie = response.headers["Set-Cookie"]
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie and "Secure" not in cookie  # plain http here
    assert client.get("/api/me").get_json() == {"user": "operator", "role": "operator", "sign_in": True,
                                                "via": "session"}
    assert client.post("/logout", content_type="application/x-www-form-urlencoded").status_code == 303  # the form
    assert client.get("/api/me").status_code == 401


def test_sign_in_goes_back_to_the_page_asked_for_but_never_off_site(signed_app):
    client = signed_app.test_client()
    back = client.post("/login", data={"username": "viewer", "password": PASSWORD, "next": "/livemap"})
    assert back.headers["Location"] == "/livemap"
    client.post("/logout")
    off_site = client.post("/login", data={"username": "viewer", "password": PASSWORD, "next": "//evil.example/"})
    assert off_site.headers["Location"] == "/"


def test_a_wrong_password_is_refused_without_saying_which_part_was_wrong(signed_app):
    client = signed_app.test_client()
    wrong = client.post("/login", data={"username": "operator", "password": "nope nope nope"})
    unknown = client.post("/login", data={"username": "nobody", "password": "nope nope nope"})
    assert wrong.status_code == unknown.status_code == 401
    assert b"wrong user name or password" in wrong.data and b"wrong user name or password" in unknown.data
    as_json = client.post("/login", json={"username": "operator", "password": "nope"})
    assert as_json.status_code == 401 and as_json.get_json()["error"] == "bad_credentials"


def test_an_api_token_works_on_any_route_and_a_revoked_one_does_not(signed_app):
    client = signed_app.test_client()
    bearer = {"Authorization": f"Bearer {signed_app.tokens['operator']}"}
    assert client.get("/api/me", headers=bearer).get_json()["via"] == "token"
    assert client.post("/api/teleop", json={"command": "stop"}, headers=bearer).status_code == 200
    admin = {"Authorization": f"Bearer {signed_app.tokens['admin']}"}
    tokens = client.get("/api/tokens", headers=admin).get_json()["tokens"]
    operator_token = next(t["id"] for t in tokens if t["user"] == "operator")
    assert client.delete(f"/api/tokens/{operator_token}", headers=admin).status_code == 200
    assert client.get("/api/me", headers=bearer).status_code == 401
    assert client.get("/api/me", headers={"Authorization": "Bearer rwt_made_up"}).status_code == 401


def test_roles_are_checked_on_the_server(signed_app):
    client = signed_app.test_client()
    viewer = {"Authorization": f"Bearer {signed_app.tokens['viewer']}"}
    operator = {"Authorization": f"Bearer {signed_app.tokens['operator']}"}
    refused = client.post("/api/teleop", json={"command": "forward"}, headers=viewer)
    assert refused.status_code == 403 and refused.get_json()["error"] == "forbidden"
    assert client.get("/api/users", headers=operator).status_code == 403
    assert client.get("/api/teleop", headers=viewer).status_code == 200


def test_a_changed_role_counts_at_the_next_request(signed_app):
    client = signed_app.test_client()
    sign_in(client, "operator")
    admin = {"Authorization": f"Bearer {signed_app.tokens['admin']}"}
    assert client.patch("/api/users/operator", json={"role": "viewer"}, headers=admin).status_code == 200
    assert client.get("/api/me").status_code == 401  # the role change ended the session
    sign_in(client, "operator")
    assert client.post("/api/teleop", json={"command": "forward"}).status_code == 403
    operator_token = {"Authorization": f"Bearer {signed_app.tokens['operator']}"}
    assert client.get("/api/me", headers=operator_token).get_json()["role"] == "viewer"  # tokens: the new role
    assert client.delete("/api/users/operator", headers=admin).status_code == 200
    assert client.get("/api/me").status_code == 401


def test_admin_manages_users_over_the_api(signed_app):
    client = signed_app.test_client()
    admin = {"Authorization": f"Bearer {signed_app.tokens['admin']}"}
    made = client.post("/api/users", json={"name": "cam", "role": "viewer", "password": "long enough"}, headers=admin)
    assert made.status_code == 201
    assert client.post("/api/users", json={"name": "cam", "role": "viewer", "password": "long enough"},
                       headers=admin).status_code == 409
    assert client.post("/api/users", json={"name": "x y", "role": "viewer", "password": "long enough"},
                       headers=admin).status_code == 400
    assert client.post("/api/users", json={"name": "z", "role": "god", "password": "long enough"},
                       headers=admin).status_code == 400
    assert client.patch("/api/users/ghost", json={"role": "viewer"}, headers=admin).status_code == 404
    names = [u["name"] for u in client.get("/api/users", headers=admin).get_json()["users"]]
    assert names == ["admin", "cam", "operator", "viewer"]
    token = client.post("/api/tokens", json={"user": "cam"}, headers=admin).get_json()["token"]
    assert client.get("/api/me", headers={"Authorization": f"Bearer {token}"}).get_json()["user"] == "cam"


def test_security_headers_on_every_response(signed_app):
    client = signed_app.test_client()
    for path in ("/login", "/api/status", "/static/js/core/api.js"):
        with client.get(path) as response:
            assert "default-src 'self'" in response.headers["Content-Security-Policy"]
            assert "frame-ancestors 'none'" in response.headers["Content-Security-Policy"]
            assert response.headers["X-Frame-Options"] == "DENY"
            assert response.headers["X-Content-Type-Options"] == "nosniff"
            assert response.headers["Referrer-Policy"] == "same-origin"


def test_the_session_key_is_made_once_and_kept_private(tmp_path):
    key = secret_key(None, str(tmp_path))
    assert len(key) == 64 and secret_key(None, str(tmp_path)) == key
    assert (tmp_path / "secret_key").stat().st_mode & 0o077 == 0
    configured = "c" * 32
    assert secret_key(configured, str(tmp_path)) == configured


def test_a_refused_user_change_changes_nothing(signed_app):
    client = signed_app.test_client()
    admin = {"Authorization": f"Bearer {signed_app.tokens['admin']}"}
    refused = client.patch("/api/users/viewer", json={"role": "admin", "password": "short"}, headers=admin)
    assert refused.status_code == 400 and refused.get_json()["error"] == "bad_password"
    assert client.get("/api/users", headers=admin).get_json()["users"][-1] == {
        "name": "viewer", "role": "viewer", "created_at": pytest.approx(0, abs=1e12), "tokens": 1}


def test_under_a_server_that_does_not_say_where_it_listens_sign_in_stays_required(app_factory):
    """auto fails closed: no flask run --host, no ROVER_WEB_HOST (another WSGI server)."""
    with pytest.raises(ConfigError, match="sign-in is required"):
        app_factory(ROVER_WEB_HOST=None)
