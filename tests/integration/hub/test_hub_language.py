"""The hub's pages in the user's language, as a robot's: Flask-Babel is set up before the app
becomes a hub, and a signed-in user's saved language holds there too."""

from __future__ import annotations

import re

from tests.integration.hub.test_hub_app import hub_app  # noqa: F401 - the fixture
from tests.support.auth import sign_in


def test_the_hub_page_is_in_the_users_language(hub_app):  # noqa: F811
    client = hub_app.test_client()
    client.set_cookie("rover_web_lang", "es")
    login = client.get("/login").get_data(as_text=True)
    assert '<html lang="es"' in login and "Iniciar sesión" in login
    assert sign_in(client, "viewer").status_code == 303
    assert client.put("/api/me/preferences", json={"language": "ja"}).status_code == 200
    page = client.get("/robots").get_data(as_text=True)  # the saved choice wins over the cookie
    assert re.search(r'<html lang="ja" data-theme="[a-z]+" data-catalogue="/static/i18n/ja\.[0-9a-f]{12}\.json">', page)
    assert "全停止" in page and "まだロボットを受信していません。" in page and "No robot heard yet." not in page
