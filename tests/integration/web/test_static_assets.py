"""Static files by content hash, pre-compressed, immutable; pages and JSON compressed, never cached so
(rover_web/web/assets.py). Through the app's real WSGI stack: WhiteNoise in front of Flask."""

import gzip
import re

import brotli

API_JS = "js/core/api.js"


def _hashed(app, name):
    return "/static/" + app.extensions["rover_web.assets"].hashed[name]


def test_a_hashed_url_is_immutable_and_served_in_the_encoding_asked_for(app, client):
    url = _hashed(app, API_JS)
    assert re.fullmatch(r"/static/js/core/api\.[0-9a-f]{12}\.js", url)
    plain = (app.static_folder + "/" + API_JS)
    original = open(plain, "rb").read()
    answers = {}
    for accept, encoding in (("br, gzip", "br"), ("gzip", "gzip"), ("", None), ("identity", None)):
        response = client.get(url, headers={"Accept-Encoding": accept})
        assert response.status_code == 200
        assert response.headers.get("Content-Encoding") == encoding, accept
        assert response.headers["Cache-Control"] == "public, max-age=31536000, immutable"
        assert "Accept-Encoding" in response.headers["Vary"]
        assert response.headers["X-Content-Type-Options"] == "nosniff"
        answers[encoding] = response.get_data()
    assert brotli.decompress(answers["br"]) == original
    assert gzip.decompress(answers["gzip"]) == original
    assert answers[None] == original
    assert len(answers["br"]) < len(original) * 0.6


def test_the_old_unhashed_url_still_answers_and_is_revalidated(client):
    response = client.get("/static/" + API_JS, headers={"Accept-Encoding": "br, gzip"})
    assert response.status_code == 200
    assert response.headers["Cache-Control"] == "no-cache"
    assert "immutable" not in response.headers["Cache-Control"]
    assert b"export" in response.get_data()


def test_a_file_that_changed_gets_a_new_url(app):
    from rover_web.web.assets import hashed_name
    assert hashed_name("js/a/b.js", "0123456789ab") == "js/a/b.0123456789ab.js"
    assert hashed_name("vendor/x-1.2/LICENSE", "0123456789ab") == "vendor/x-1.2/LICENSE.0123456789ab"


def test_pages_and_api_answers_are_compressed_but_never_cached_as_immutable(client):
    page = client.get("/", headers={"Accept-Encoding": "br, gzip"})
    assert page.status_code == 200
    assert page.headers["Content-Encoding"] == "br"
    assert "Accept-Encoding" in page.headers["Vary"]
    assert "immutable" not in page.headers.get("Cache-Control", "")
    html = brotli.decompress(page.get_data()).decode()
    # Static URLs in the page are the hashed ones: its bundle, and in the import map each module.
    assert re.search(r'<script type="module" src="/static/js/bundle/[0-9a-f]{12}\.js"></script>', html)
    imports = re.search(r'<script type="importmap" nonce="[^"]+">(.*?)</script>', html).group(1)
    assert '"/static/js/core/api.js":"/static/js/core/api.' in imports
    assert html.index('type="importmap"') < html.index('type="module"')
    gz = client.get("/api/openapi.json", headers={"Accept-Encoding": "gzip"})
    assert gz.headers["Content-Encoding"] == "gzip"
    assert gzip.decompress(gz.get_data()).startswith(b"{")
    assert "immutable" not in gz.headers.get("Cache-Control", "")
    small = client.get("/api/estop", headers={"Accept-Encoding": "br, gzip"})
    assert "Content-Encoding" not in small.headers  # below the size where compressing pays
    plain = client.get("/", headers={"Accept-Encoding": "identity"})
    assert "Content-Encoding" not in plain.headers and b"</html>" in plain.get_data()


def test_unbundled_every_module_a_page_imports_statically_is_preloaded(app_factory):
    # ROVER_WEB_BUNDLE off (or no esbuild): the page's own module scripts, and the rest named up front.
    app = app_factory(ROVER_WEB_BUNDLE=False)
    manifest = app.extensions["rover_web.assets"]
    html = app.test_client().get("/").get_data(as_text=True)
    assert 'src="/static/js/live/live.' in html and 'src="/static/js/live/live.js"' not in html
    entries = [manifest.plain_of[src[len("/static/"):]]
               for src in re.findall(r'<script type="module" src="([^"]+)"', html)]
    preloaded = {manifest.plain_of[href[len("/static/"):]]
                 for href in re.findall(r'<link rel="modulepreload" href="([^"]+)"', html)}
    eager, _ = manifest.closure(entries)
    assert set(eager) - set(entries) == preloaded
    assert "js/core/api.js" in preloaded and "js/live/shared_stream.js" in preloaded


def test_the_drawn_basemap_and_big_json_are_compressed_and_the_event_stream_is_not(app):
    client = app.test_client()
    basemap = client.get("/basemap/benderson_park", headers={"Accept-Encoding": "gzip"})
    assert basemap.status_code == 200 and basemap.headers["Content-Encoding"] == "gzip"
    with client.get("/api/events?channels=status", headers={"Accept-Encoding": "br, gzip"},
                    buffered=False) as events:
        assert events.mimetype == "text/event-stream"
        assert "Content-Encoding" not in events.headers
