"""The pages' shared event stream (static/js/live/shared_stream.js) hands a tab that joins the newest
value of each channel, except on the channels the server emits into its ring: those events count
one by one, and an old one must not look new. The browser cannot tell the two kinds apart, so the
list is written out there; this test keeps it equal to the channels the server's code emits on."""

import ast
import re

from rover_web.config import ROOT


def emitted_channels() -> set[str]:
    found = set()
    for path in sorted((ROOT / "rover_web").rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        constants = {target.id: node.value.value for node in tree.body if isinstance(node, ast.Assign)
                     for target in node.targets
                     if isinstance(target, ast.Name) and isinstance(node.value, ast.Constant)}
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "emit"
                    and ast.unparse(node.func.value).endswith("hub")):
                continue
            arg = node.args[0]
            channel = arg.value if isinstance(arg, ast.Constant) else constants.get(getattr(arg, "id", None))
            assert isinstance(channel, str), f"{path}:{node.lineno}: name the channel in a constant of that module"
            found.add(channel)
    return found


def test_the_pages_ring_channels_are_the_ones_the_server_emits_on():
    source = (ROOT / "static" / "js" / "live" / "shared_stream.js").read_text()
    listed = re.search(r"RING_CHANNELS = new Set\(\[([^\]]*)\]\)", source).group(1)
    assert set(re.findall(r"'([a-z0-9_]+)'", listed)) == emitted_channels() == {"scan_code", "panel_log", "plot"}
