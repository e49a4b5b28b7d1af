"""Strict-Transport-Security: sent over https, never over plain http (issue 27)."""


def test_hsts_over_https_only(client):
    for path in ("/", "/api/status", "/login"):
        with client.get(path, base_url="https://localhost") as secure:
            assert secure.headers["Strict-Transport-Security"] == "max-age=31536000", path
        with client.get(path) as plain:
            assert "Strict-Transport-Security" not in plain.headers, path
