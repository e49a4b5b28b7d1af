"""Each page's modules as one esbuild bundle, its stylesheets as one file (rover_web/web/bundles.py):
what a bundle holds, that it is served like every hashed file, and that a changed module changes it.
Real esbuild (scripts/bootstrap.sh installs it into .tools/)."""

import json
import os
import re
from pathlib import Path

import brotli
import pytest

from rover_web.web import assets
from rover_web.web.bundles import ESBUILD_VERSION, Bundles, find_esbuild

ROOT = Path(__file__).resolve().parents[3]
ESBUILD = find_esbuild(ROOT)
# scripts/test.sh runs bootstrap, which installs it: without it these tests fail, they do not skip.


def test_bootstrap_installed_the_pinned_esbuild():
    import subprocess
    assert ESBUILD is not None, "esbuild missing: run scripts/bootstrap.sh (it installs it into .tools/)"
    assert subprocess.run([ESBUILD, "--version"], capture_output=True, text=True).stdout.strip() == ESBUILD_VERSION


def _page_parts(client, path):
    html = client.get(path).get_data(as_text=True)
    scripts = re.findall(r'<script type="module" src="/static/([^"]+)"></script>', html)
    sheets = re.findall(r'<link rel="stylesheet" href="/static/([^"]+)">', html)
    return html, scripts, sheets


@pytest.mark.parametrize("path", ["/", "/waypoints", "/robots", "/plot?topic=/odom&field=twist.twist.linear.x",
                                  "/recordings", "/3d"])
def test_a_page_loads_one_bundle_holding_every_module_it_ran_one_by_one(app_factory, path):
    bundled = app_factory().test_client()
    one_by_one_app = app_factory(ROVER_WEB_BUNDLE=False)
    manifest = one_by_one_app.extensions["rover_web.assets"]
    _, entries, sheets_before = _page_parts(one_by_one_app.test_client(), path)
    entries = [manifest.plain_of[e] for e in entries]
    html, scripts, sheets = _page_parts(bundled, path)

    assert len(scripts) == 1 and re.fullmatch(r"js/bundle/[0-9a-f]{12}\.js", scripts[0]), scripts
    # In the head, after the import map, so its download starts with the page's first bytes.
    assert html.index('type="importmap"') < html.index(scripts[0]) < html.index("</head>")
    assert "modulepreload" not in html or path == "/3d"  # only what stays outside (three.js) is preloaded
    answer = bundled.get("/static/" + scripts[0], headers={"Accept-Encoding": "br"})
    assert answer.status_code == 200 and answer.headers["Content-Encoding"] == "br"
    assert answer.headers["Cache-Control"] == "public, max-age=31536000, immutable"
    code = brotli.decompress(answer.get_data()).decode()
    # The bundle's source map names its sources: every module the page ran one by one, and their imports.
    map_name = re.search(r"//# sourceMappingURL=(\S+)", code).group(1)
    source_map = bundled.get("/static/js/bundle/" + map_name)
    assert source_map.status_code == 200
    # Named from where the bundle is served ('../core/api.js'), never by the server's own paths.
    sources = {os.path.normpath(os.path.join("js/bundle", s)) for s in json.loads(source_map.get_data())["sources"]}
    assert not [s for s in sources if str(ROOT) in s or s.startswith("..")], sources
    eager, _ = manifest.closure(entries)
    assert {m for m in eager if m.startswith("js/")} <= sources, set(eager) - sources
    # Each of the page's modules in its own import(), in the page's order: one that throws stops only
    # itself. esbuild writes each as Promise.resolve().then(...), or, once a module of the page awaits
    # at its top level (core/i18n.js, for its catalogue), as a call of the module's async init.
    assert code.count("Promise.resolve().then(") >= len(entries) or "async()=>" in code

    # The stylesheets: the joinable ones as one file, in their order, each named in it.
    joined = [s for s in sheets if s.startswith("css/bundle/")]
    assert len(joined) == 1 and len(sheets) < len(sheets_before)
    text = bundled.get("/static/" + joined[0], headers={"Accept-Encoding": "identity"}).get_data(as_text=True)
    names = re.findall(r"^/\* (\S+\.css) \*/$", text, re.MULTILINE)
    plain_before = [manifest.plain_of[s] for s in sheets_before]
    assert names == [s for s in plain_before if s in names] and len(names) >= 2
    assert set(plain_before) == set(names) | {manifest.plain_of.get(s) for s in sheets if s not in joined}


def _tree(tmp_path, files):
    static = tmp_path / "static"
    for name, text in files.items():
        (static / name).parent.mkdir(parents=True, exist_ok=True)
        (static / name).write_text(text)
    return static


def _bundles(static, store_dir, made):
    manifest = assets.build(static, store_dir)

    def serve(name, data):
        assets.store(store_dir, name, data)
        made.append(name)

    return manifest, Bundles(static, store_dir, manifest.hashed, serve, ESBUILD)


def test_a_changed_module_changes_the_bundle_and_its_url(tmp_path):
    static = _tree(tmp_path, {
        "js/core/api.js": "export const where = 'one';\n",
        "js/page/a.js": "import { where } from '../core/api.js';\nwindow.seen = [where];\n",
        "js/page/b.js": "import { where } from '../core/api.js';\nwindow.seen.push(where + 'b');\n",
    })
    store_dir = tmp_path / "store"
    made = []
    _, bundles = _bundles(static, store_dir, made)
    first = bundles.scripts(["js/page/a.js", "js/page/b.js"])
    assert first and (store_dir / first).is_file() and (store_dir / (first + ".br")).is_file()
    code = (store_dir / first).read_text()
    assert code.count("'one'") + code.count('"one"') == 1  # the shared module once
    # A later start finds it in the store without esbuild.
    _, again = _bundles(static, store_dir, made)
    again.esbuild = "/nonexistent/esbuild"
    assert again.scripts(["js/page/a.js", "js/page/b.js"]) == first
    # The shared module changes: a new bundle under a new name; the old one stays for pages still open.
    (static / "js/core/api.js").write_text("export const where = 'two';\n")
    _, changed = _bundles(static, store_dir, made)
    second = changed.scripts(["js/page/a.js", "js/page/b.js"])
    assert second and second != first and "two" in (store_dir / second).read_text()
    assert (store_dir / first).is_file()
    # Another order of entries is another bundle (the modules run in the page's order).
    assert changed.scripts(["js/page/b.js", "js/page/a.js"]) not in (None, second)


def test_what_cannot_be_bundled_is_served_one_by_one(tmp_path):
    static = _tree(tmp_path, {
        "js/page/a.js": "import '../page/missing.js';\n",
        "js/page/b.js": "window.here = new URL('./data.json', import.meta.url);\n",
        "css/a.css": "a { color: red; }\n",
        "css/b.css": "b { color: blue; }\n",
        "css/c.css": "c { background: url(img/x.png); }\n",
        "css/d.css": "d { background: url(\"data:image/svg+xml,<svg/>\"); }\n",
    })
    _, bundles = _bundles(static, tmp_path / "store", [])
    assert bundles.scripts(["js/page/a.js"]) is None  # esbuild refused it: the page keeps its script tags
    assert bundles.scripts(["js/page/b.js"]) is None  # its own URL would be the bundle's
    name, joined = bundles.styles(["css/a.css", "css/c.css", "css/b.css", "css/d.css"])
    assert joined == ["css/a.css", "css/b.css", "css/d.css"]  # a relative url() would point elsewhere
    assert name.startswith("css/bundle/")
    assert Bundles(static, tmp_path / "s2", {}, lambda n, d: None, None).scripts(
        ["js/page/a.js"]) is None  # no esbuild: no bundle
