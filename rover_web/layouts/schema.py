"""A layout document, version 1, and its validation. Pure Python (jsonschema, no Flask).

    {"version": 1, "name": "Boat", "cards": [{"type": "camera", "x": 4, "y": 0, "w": 8, "h": 6,
                                              "settings": {"topic": "/camera/image_raw"}}]}

The grid is COLUMNS wide and at most ROWS tall; x and y count cells from the top left. The shape is
checked with JSON Schema (the same schema /api/openapi.json shows), each card's settings against its
type's own schema, then what a schema cannot say: cards inside the grid, none overlapping, and one
of each card type that may appear once. The first problem found is reported with the field it is
in ("cards[2].settings.topic"), and nothing is stored.
"""

from __future__ import annotations

import functools
from typing import Any

from rover_web.web.api_messages import explain

from .cards import CARDS

VERSION = 1
COLUMNS = 12
ROWS = 100
MAX_CARDS = 24
NAME_MAX = 60

CARD_SCHEMA = {
    "type": "object",
    "properties": {
        "type": {"enum": sorted(CARDS)},
        "x": {"type": "integer", "minimum": 0, "maximum": COLUMNS - 1},
        "y": {"type": "integer", "minimum": 0, "maximum": ROWS - 1},
        "w": {"type": "integer", "minimum": 1, "maximum": COLUMNS},
        "h": {"type": "integer", "minimum": 1, "maximum": ROWS},
        "settings": {"type": "object"},
    },
    "required": ["type", "x", "y", "w", "h"],
    "additionalProperties": False,
}
LAYOUT_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "rover_web dashboard layout, version 1",
    "type": "object",
    "properties": {
        "version": {"const": VERSION},
        # Not blank; no control characters or lone surrogates (neither prints, and SQLite and the
        # page's UTF-8 cannot hold a surrogate).
        "name": {"type": "string", "minLength": 1, "maxLength": NAME_MAX,
                 "pattern": "^(?=.*\\S)[^\\u0000-\\u001f\\u007f-\\u009f\\ud800-\\udfff]+(?![\\s\\S])"},
        "cards": {"type": "array", "maxItems": MAX_CARDS, "items": CARD_SCHEMA},
    },
    "required": ["version", "name", "cards"],
    "additionalProperties": False,
}


@functools.cache
def _validators():
    """Made at the first validation: jsonschema and its dependencies are ~9 MB a robot with no
    layout edit never needs (issue 32's idle memory)."""
    from jsonschema import Draft202012Validator

    return (Draft202012Validator(LAYOUT_SCHEMA),
            {name: Draft202012Validator(card.settings) for name, card in CARDS.items()})

# jsonschema's keyword -> the API's error code (web/validate.py uses the same words)
CODES = {"required": "missing_field", "additionalProperties": "unknown_field", "type": "bad_type",
         "maxLength": "too_long", "minLength": "too_short", "maxItems": "too_many", "minItems": "too_few",
         "enum": "bad_value", "const": "bad_version", "pattern": "bad_value", "minimum": "out_of_range",
         "maximum": "out_of_range"}


class InvalidLayout(ValueError):
    """What is wrong, where (`field`, e.g. "cards[2].w") and a short code."""

    def __init__(self, field: str, message: str, code: str):
        super().__init__(explain("%(field)s: %(why)s", field=field, why=message) if field else message)
        self.field, self.code = field, code


def field_name(path) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _first_error(validator, doc: Any, prefix: list) -> None:
    errors = sorted(validator.iter_errors(doc), key=lambda e: (list(map(str, e.absolute_path)), e.validator))
    if not errors:
        return
    error = errors[0]
    path = prefix + list(error.absolute_path)
    message = error.message
    if error.validator == "required":
        missing = message.split("'")[1] if message.count("'") >= 2 else ""
        path.append(missing)
        why_text = explain("is required")
    elif error.validator == "additionalProperties":
        allowed = ", ".join(sorted(error.schema.get("properties", {})))
        if allowed:
            why_text = explain("%(why)s; allowed: %(allowed)s", why=message, allowed=allowed)
        else:
            why_text = explain("%(why)s; allowed: none", why=message)
    elif error.validator == "const" and path == ["version"]:
        why_text = explain("this server reads layout version %(version)s; got %(got)s", version=VERSION,
                           got=repr(error.instance)[:20])
    elif error.validator == "maxLength":
        why_text = explain("is longer than %(max_len)s characters", max_len=error.validator_value)
    elif error.validator == "maxItems":
        why_text = explain("holds more than %(max_items)s items", max_items=error.validator_value)
    elif error.validator == "enum":
        why_text = explain("%(got)s is not one of %(choices)s", got=repr(error.instance)[:40],
                           choices=", ".join(map(str, error.validator_value)))
    elif error.validator == "pattern" and path and path[-1] == "name":
        why_text = explain("must not be blank or hold control characters")
    elif error.validator == "pattern":
        why_text = explain("%(got)s is not valid here", got=repr(error.instance)[:80])
    else:  # jsonschema's own English words, as they are
        why_text = explain("%(why)s", why=message if len(message) <= 200 else message[:200] + "…")
    raise InvalidLayout(field_name(path), why_text, CODES.get(error.validator, "bad_value"))


def validate(doc: Any) -> dict:
    """The layout, checked and normalised (settings always present, integers as int); InvalidLayout if not."""
    if not isinstance(doc, dict):
        raise InvalidLayout("", explain("a layout is a JSON object"), "bad_json")
    layout_validator, settings_validators = _validators()
    _first_error(layout_validator, doc, [])
    cards = []
    taken: dict[tuple[int, int], int] = {}
    seen_once: dict[str, int] = {}
    for i, raw in enumerate(doc["cards"]):
        card = CARDS[raw["type"]]
        where = f"cards[{i}]"
        values = {k: settings_value(v) for k, v in raw.get("settings", {}).items()}
        _first_error(settings_validators[card.name], values, ["cards", i, "settings"])
        x, y, w, h = (int(raw[k]) for k in ("x", "y", "w", "h"))
        if x + w > COLUMNS:
            raise InvalidLayout(f"{where}.w", explain("x + w is %(value)s: the grid is %(columns)s columns wide",
                                                      value=x + w, columns=COLUMNS), "out_of_grid")
        if y + h > ROWS:
            raise InvalidLayout(f"{where}.h", explain("y + h is %(value)s: the grid is at most %(rows)s rows tall",
                                                      value=y + h, rows=ROWS),
                                "out_of_grid")
        once_key = card.name + (f":{values.get('panel', '')}" if card.name == "panel" else "")
        if card.once or card.name == "panel":
            if once_key in seen_once:
                if card.name == "panel":
                    why_text = explain("a layout holds at most one %(card)s card per panel (cards[%(other)s] is one)",
                                       card=card.name, other=seen_once[once_key])
                else:
                    why_text = explain("a layout holds at most one %(card)s card (cards[%(other)s] is one)",
                                       card=card.name, other=seen_once[once_key])
                raise InvalidLayout(f"{where}.type", why_text, "duplicate_card")
            seen_once[once_key] = i
        for cx in range(x, x + w):
            for cy in range(y, y + h):
                if (cx, cy) in taken:
                    raise InvalidLayout(where, explain("overlaps cards[%(taken)s] at x=%(cx)s, y=%(cy)s",
                                                       taken=taken[cx, cy], cx=cx, cy=cy), "overlap")
                taken[cx, cy] = i
        cards.append({"type": card.name, "x": x, "y": y, "w": w, "h": h, "settings": values})
    return {"version": VERSION, "name": doc["name"].strip(), "cards": cards}


def settings_value(value: Any) -> Any:
    """Whole floats (2.0, as JSON allows for integers) become ints, so the stored JSON is canonical."""
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, list):
        return [settings_value(v) for v in value]
    if isinstance(value, dict):
        return {k: settings_value(v) for k, v in value.items()}
    return value
