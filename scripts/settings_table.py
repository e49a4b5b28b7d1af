"""Print the README's settings table from rover_web/settings.py (the one place defaults live)."""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from rover_web.config import PREFIX, SETTINGS  # noqa: E402

print("| setting | default | meaning |")
print("| --- | --- | --- |")
for s in SETTINGS:
    default = "unset" if s.default is None else json.dumps(s.default) if not isinstance(s.default, str) else s.default
    print(f"| `{PREFIX}{s.name}` | `{default}` | {s.meaning} |")
