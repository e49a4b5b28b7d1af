"""Rewrite the settings table in docs/configuration.md from rover_web/settings.py."""

import subprocess
import sys
from pathlib import Path

root = Path(__file__).resolve().parent.parent
readme = root / "docs" / "configuration.md"
table = subprocess.run([sys.executable, str(root / "scripts" / "settings_table.py")], check=True,
                       capture_output=True, text=True).stdout
text = readme.read_text()
begin = text.index("<!-- settings:begin")
begin = text.index("\n", begin) + 1
end = text.index("<!-- settings:end -->")
readme.write_text(text[:begin] + table + text[end:])
