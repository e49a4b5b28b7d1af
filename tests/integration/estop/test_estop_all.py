"""POST /api/estop/all takes the body POST /api/estop engages with and refuses a release; the
sign-in page's e-stop engages every robot for anyone who reaches it, and never releases (issue 27)."""

import pytest

from tests.support.auth import PASSWORD


def latch(client, headers=None):
    return client.get("/api/estop", headers=headers or {}).get_json()


def test_estop_all_engages_with_engaged_true_or_an_empty_body(app_factory):
    # Engaging works whatever else the body says, as with POST /api/estop.
    for body in ({"engaged": True}, {"engaged": True, "by": "chief"}, {"engaged": True, "release": True},
                 {"engaged": True, "by": 5}, {}, {"by": "chief"}, None):
        client = app_factory().test_client()
        if body is None:  # no body at all (JSON content type, as the page's fetch sends it)
            answer = client.post("/api/estop/all", content_type="application/json")
        else:
            answer = client.post("/api/estop/all", json=body)
        assert answer.status_code == 200, (body, answer.get_json())
        assert answer.get_json()["engaged"] is True
        assert latch(client)["engaged"] is True


@pytest.mark.parametrize("body,code", [
    ({"engaged": False}, "release_per_robot"),
    ({"engaged": False, "by": "chief"}, "release_per_robot"),
    ({"engaged": "yes"}, "bad_type"),
    ({"engaged": None}, "bad_type"),
    ({"release": True}, "unknown_field"),
    ({"by": 5}, "bad_type"),
])
def test_estop_all_refuses_a_release_and_bad_bodies_and_changes_nothing(client, body, code):
    assert latch(client)["engaged"] is False
    refused = client.post("/api/estop/all", json=body)
    assert refused.status_code == 400 and refused.get_json()["error"] == code
    if code == "release_per_robot":
        assert "per robot" in refused.get_json()["message"]
    assert latch(client)["engaged"] is False


def test_estop_all_release_is_refused_while_engaged_too(client):
    assert client.post("/api/estop/all", json={"engaged": True}).status_code == 200
    assert client.post("/api/estop/all", json={"engaged": False}).status_code == 400
    assert latch(client)["engaged"] is True


def test_the_sign_in_page_offers_an_engage_only_e_stop_to_anyone(signed_app):
    viewer = {"Authorization": f"Bearer {signed_app.tokens['viewer']}"}
    anonymous = signed_app.test_client()
    page = anonymous.get("/login")
    assert b'action="/login/estop"' in page.data
    assert anonymous.post("/api/estop", json={"engaged": True}).status_code == 401  # the API still needs sign-in
    engaged = anonymous.post("/login/estop", content_type="application/x-www-form-urlencoded")
    assert engaged.status_code == 200 and engaged.mimetype == "text/html"
    assert b"E-stop engaged on every robot" in engaged.data
    state = latch(anonymous, viewer)
    assert state["engaged"] is True and state["by"] == "sign-in page (127.0.0.1)"
    # Never a release: not from the page, and not through the API without an operator.
    assert anonymous.post("/login/estop", json={"engaged": False}).get_json()["engaged"] is True
    assert anonymous.post("/api/estop", json={"engaged": False}).status_code == 401
    assert latch(anonymous, viewer)["engaged"] is True


def test_the_sign_in_page_e_stop_refuses_a_foreign_origin(signed_app):
    viewer = {"Authorization": f"Bearer {signed_app.tokens['viewer']}"}
    client = signed_app.test_client()
    refused = client.post("/login/estop", content_type="application/x-www-form-urlencoded",
                          headers={"Origin": "http://evil.example"})
    assert refused.status_code == 403 and refused.get_json()["error"] == "foreign_origin"
    assert latch(client, viewer)["engaged"] is False


def test_the_sign_in_page_e_stop_is_limited_per_address(signed_app):
    client = signed_app.test_client()
    statuses = [client.post("/login/estop", json={}).status_code for _ in range(7)]
    assert statuses == [200] * 6 + [429]
    limited = client.post("/login/estop", content_type="application/x-www-form-urlencoded")
    assert limited.status_code == 429 and int(limited.headers["Retry-After"]) >= 1
    assert b"already engaged" in limited.data
    other = signed_app.test_client()
    other.environ_base["REMOTE_ADDR"] = "10.0.0.2"
    assert other.post("/login/estop", json={}).status_code == 200


def test_the_sign_in_page_e_stop_over_its_limit_still_stops_a_released_robot(signed_app):
    """The limit bounds presses that change nothing; an address that spent it (a NAT, a proxy
    shared with whoever pressed before) must still be able to stop a robot an operator released."""
    operator = {"Authorization": f"Bearer {signed_app.tokens['operator']}"}
    client = signed_app.test_client()
    assert [client.post("/login/estop", json={}).status_code for _ in range(6)] == [200] * 6
    assert client.post("/api/estop", json={"engaged": False}, headers=operator).get_json()["engaged"] is False
    again = client.post("/login/estop", content_type="application/x-www-form-urlencoded")
    assert again.status_code == 200 and b"E-stop engaged on every robot" in again.data
    assert latch(client, operator)["engaged"] is True
    # Now there is nothing left to stop: the press over the limit is refused.
    assert client.post("/login/estop", json={}).status_code == 429


def test_the_sign_in_page_e_stop_can_be_turned_off(app_factory, tmp_path):
    from tests.support.auth import add_users

    db_path = tmp_path / "off.sqlite3"
    add_users(db_path)
    app = app_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path), ROVER_WEB_LOGIN_ESTOP=False)
    client = app.test_client()
    assert b"/login/estop" not in client.get("/login").data
    assert client.post("/login/estop", json={}).status_code == 404
    assert client.post("/login", json={"username": "viewer", "password": PASSWORD}).status_code == 200
    assert latch(client)["engaged"] is False
