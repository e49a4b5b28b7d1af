"""Each user's theme and language over REST, in the app's real SQLite file."""

import sqlite3

import pytest

from rover_web.storage.db import database_path
from tests.support.auth import sign_in


def test_with_sign_in_off_the_choices_are_the_browsers_and_cookies_carry_them(client):
    got = client.get("/api/me/preferences").get_json()
    assert got["effective"] == {"theme": "auto", "language": "auto"} and got["kept"] == "browser"
    refused = client.put("/api/me/preferences", json={"theme": "daylight"})
    assert refused.status_code == 409 and refused.get_json()["error"] == "no_user"
    client.set_cookie("rover_web_theme", "daylight")
    client.set_cookie("rover_web_lang", "ja")
    assert client.get("/api/me/preferences").get_json()["effective"] == {"theme": "daylight", "language": "ja"}
    client.set_cookie("rover_web_theme", "<script>")  # not a theme: ignored, never echoed
    assert client.get("/api/me/preferences").get_json()["effective"]["theme"] == "auto"


def test_a_users_choices_are_kept_on_the_robot_and_follow_them_to_another_browser(signed_app, tmp_path):
    first = signed_app.test_client()
    sign_in(first, "viewer")
    first.set_cookie("rover_web_theme", "dark")  # this browser's own choice ...
    saved = first.put("/api/me/preferences", json={"theme": "daylight", "language": "es"})
    assert saved.status_code == 200, saved.get_json()
    assert saved.get_json() == {"saved": {"theme": "daylight", "language": "es"}, "user": "viewer"}
    # ... is overruled by the user's saved one, here and in a new browser after signing in.
    assert first.get("/api/me/preferences").get_json()["effective"] == {"theme": "daylight", "language": "es"}
    second = signed_app.test_client()
    assert second.get("/api/me/preferences").status_code == 401
    sign_in(second, "viewer")
    got = second.get("/api/me/preferences").get_json()
    assert got["kept"] == "user" and got["saved"] == {"theme": "daylight", "language": "es"}
    # Another user has their own; a partial change keeps the other field.
    other = signed_app.test_client()
    sign_in(other, "operator")
    assert other.get("/api/me/preferences").get_json()["saved"] == {}
    assert first.put("/api/me/preferences", json={"language": "ja"}).get_json()["saved"] == {
        "theme": "daylight", "language": "ja"}
    # With a bearer token too (curl).
    token = {"Authorization": f"Bearer {signed_app.tokens['viewer']}"}
    assert signed_app.test_client().get("/api/me/preferences", headers=token).get_json()["saved"]["language"] == "ja"


@pytest.mark.parametrize("body, code", [
    ({"theme": "pink"}, "bad_value"),
    ({"theme": 1}, "bad_type"),
    ({"language": "de"}, "bad_value"),
    ({"language": None}, "bad_type"),
    ({"font": "big"}, "unknown_field"),
    ({"theme": "daylight", "font": "big"}, "unknown_field"),
    ([], "bad_json"),
])
def test_bad_choices_are_refused_and_change_nothing(signed_app, body, code):
    client = signed_app.test_client()
    sign_in(client, "viewer")
    assert client.put("/api/me/preferences", json={"theme": "dark"}).status_code == 200
    answer = client.put("/api/me/preferences", json=body)
    assert answer.status_code == 400, answer.get_json()
    assert answer.get_json()["error"] == code
    assert client.get("/api/me/preferences").get_json()["saved"] == {"theme": "dark"}
    with sqlite3.connect(database_path(signed_app)) as conn:
        assert conn.execute("SELECT theme, language FROM user_preferences").fetchall() == [("dark", None)]
