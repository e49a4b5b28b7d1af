"""Where an API error's message is written, and whether `pybabel extract` can read it there.

Shared by the catalogue test and scripts: the keywords here are the ones docs/i18n_api.md gives the
lead for babel.cfg.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
PACKAGE = ROOT / "rover_web"

# callable name -> index (0-based) of its message argument. Babel's spec is 1-based: NAME:index+1.
MESSAGE_ARG = {
    "ApiError": 2,
    "error_response": 2,
    "InvalidInput": 0,
    "explain": 0,
}
KEYWORDS = [f"{name}:{index + 1}" for name, index in MESSAGE_ARG.items()]
# A sentence pushed to every viewer: extracted on its own into events.pot (translations/events_babel.cfg).
SAID_ARG = {"said": 0}
EVENT_KEYWORDS = [f"{name}:{index + 1}" for name, index in SAID_ARG.items()]
LITERAL_ARG = {**MESSAGE_ARG, **SAID_ARG}

# A message that is not a literal may only be a Text carried from where it was written and extracted.
CARRIERS = {"text_of", "explain", "said", "_http_text"}

# Exceptions whose message reaches a user as an API error's `message` (or a teleop frame's): their
# message argument (0-based index) must be an explain(...) or said(...) Text, so it is extracted and translated.
REFUSALS = {
    "AccountError": 0, "AdminRefused": 2, "AmbiguousType": 0, "BadFeatures": 0, "CannotSubscribe": 0,
    "CommandRefused": 0, "EchoRefused": 0, "FieldError": 1, "FrameError": 1, "GoalRejected": 0, "HashingBusy": 0,
    "ImportRefused": 0, "InvalidCommand": 0, "InvalidLayout": 1, "InvalidValue": 0, "MeshRefused": 2,
    "Nav2Unavailable": 1, "NoGoal": 0, "NotARecording": 0, "NotPlottable": 0, "NotShown": 1, "OutsideGeofence": 0,
    "OutsideMap": 0, "PanelError": 0, "ParameterRefused": 2, "Refused": 1, "ReleaseRefused": 1,
    "SchemaNotFound": 0, "ShuttingDown": 0, "StreamRefused": 0, "TfError": 1, "TooCostly": 1, "TooMany": 0,
    "TooManyClients": 0, "TooManySeries": 0, "TooManyStreams": 1, "Unavailable": 0, "UnknownControl": 0,
    "UnknownMap": 0, "UnknownMessageType": 0, "UnknownPanel": 0, "UnknownTopic": 0, "UnknownType": 0, "UrdfError": 0,
    "_bad": 0,  # ros_admin/parameters.py: a ParameterRefused(400, ...)
    "Refusal": 1,  # panels/state.py: why a control cannot be used now
    "too_many": 0,  # web/http.py: what there were too many of (429)
    "NoAnswer": 0,  # ros/admin.py, ros/goal_client.py: a ROS server that did not answer in time
}
# The same name for another class in these folders (a different signature), and what is not a user's.
REFUSAL_OVERRIDES = {("FieldError", "rover_web/plot/"): 0, ("FrameError", "rover_web/camera/"): 0,
                     ("CommandRefused", "rover_web/zenoh_link/"): None}


def refusal_index(name: str, path: str) -> int | None:
    for (cls, folder), index in REFUSAL_OVERRIDES.items():
        if cls == name and path.startswith(folder):
            return index
    return REFUSALS.get(name)


def _name(func: ast.expr) -> str | None:
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return None


def _carried(arg: ast.expr) -> bool:
    """A Text made where its msgid was written: `exc.text`, a `why_text` variable, text_of(exc), explain(...)."""
    if isinstance(arg, ast.Attribute) and arg.attr.endswith("text"):
        return True
    if isinstance(arg, ast.Name) and arg.id.endswith("text"):
        return True
    return isinstance(arg, ast.Call) and _name(arg.func) in CARRIERS


def problems(root: Path = PACKAGE) -> list[str]:
    """Every call site whose message pybabel could not extract (an f-string, a variable...)."""
    found = []
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = _name(node.func)
            where = f"{path.relative_to(ROOT)}:{node.lineno} {name}"
            if name in REFUSALS:
                index = refusal_index(name, str(path.relative_to(ROOT)))
                if index is None or len(node.args) <= index:
                    continue
                arg = node.args[index]
                if not _carried(arg):
                    found.append(f"{where}: message is {type(arg).__name__}, not explain(\"...\") or a carried Text")
                continue
            if name not in LITERAL_ARG:
                continue
            index = LITERAL_ARG[name]
            if any(isinstance(a, ast.Starred) for a in node.args[:index + 1]):
                found.append(f"{where}: *args hide the message")
                continue
            if len(node.args) <= index:
                if name in ("ApiError", "InvalidInput") and any(k.arg == "message" for k in node.keywords):
                    found.append(f"{where}: message given by keyword; pass it positionally")
                elif name not in ("ApiError", "error_response", "InvalidInput", "explain", "said"):
                    continue
                else:
                    found.append(f"{where}: no message")
                continue
            arg = node.args[index]
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                continue
            if name not in ("explain", "said") and _carried(arg):
                continue
            kind = "an f-string" if isinstance(arg, ast.JoinedStr) else type(arg).__name__
            found.append(f"{where}: message is {kind}, not a literal msgid")
    return found


if __name__ == "__main__":
    for line in problems():
        print(line)
