"""requirements.lock (what deployments install, with hashes) pins every dependency of the app, its
`ros` and `serve` extras at a version pyproject.toml allows, with a hash, and no test tool."""

import re
import tomllib

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

from rover_web.config import ROOT

PIN = re.compile(r"^([A-Za-z0-9_.-]+)==([^ \\]+)", re.MULTILINE)


def locked() -> dict[str, tuple[Version, str]]:
    text = (ROOT / "requirements.lock").read_text()
    blocks = re.split(r"\n(?=[A-Za-z0-9])", text)
    pins = {}
    for block in blocks:
        if m := PIN.match(block):
            pins[canonicalize_name(m.group(1))] = (Version(m.group(2)), block)
    return pins


def test_the_lock_pins_every_runtime_dependency_within_pyproject_bounds_with_hashes():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    wanted = [Requirement(r) for r in project["dependencies"] + project["optional-dependencies"]["ros"]
              + project["optional-dependencies"]["serve"]]
    pins = locked()
    for requirement in wanted:
        name = canonicalize_name(requirement.name)
        assert name in pins, f"{name} is not in requirements.lock: regenerate it (docs/deploying.md)"
        version, block = pins[name]
        assert requirement.specifier.contains(version, prereleases=True), f"{name}=={version} vs {requirement}"
    assert all("--hash=sha256:" in block for _, block in pins.values())


def test_the_lock_holds_no_test_tool():
    pins = locked()
    for tool in ("pytest", "hypothesis", "playwright", "schemathesis", "ruff", "uv"):
        assert tool not in pins
