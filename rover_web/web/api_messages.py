"""The `message` of an API error: an English msgid and its values, translated where the answer is made.

A refusal is written once, where it is decided, as an English msgid with `%(name)s` placeholders and
the values that fill them: `ApiError(404, "not_found", "no layout %(id)s on this robot", id=layout_id)`.
It stays English in logs and in `str(exc)`; only the JSON answer (or a WebSocket frame) renders it in
the request's language, so a site stays one line and `pybabel extract` finds every msgid by keyword
(the keywords are in docs/i18n_api.md). Values are never translated (topic names, numbers, codes),
unless a value is itself a Text (a reason given by another part, e.g. a layout's schema error).

The error `code` is never translated: clients branch on it.
"""

from __future__ import annotations

import logging
from typing import Any

from flask import current_app, has_request_context
from flask_babel import get_domain

log = logging.getLogger(__name__)



class Text(str):
    """An English msgid and the values that fill its placeholders.

    It is also the English text itself (a str): code that compares, searches, logs or serialises a
    reason keeps working with the English, and only `translated()` gives the request's language.
    """

    msgid: str
    values: dict[str, Any]

    def __new__(cls, msgid: str, values: dict[str, Any] | None = None):
        values = values or {}
        text = super().__new__(cls, _fill(msgid, values, str))
        text.msgid, text.values = msgid, values
        return text

    def english(self) -> str:
        return str.__str__(self)

    def translated(self, catalogues: tuple | None = None) -> str:
        """In the request's language when a catalogue has it; the English otherwise, never an error.

        `catalogues` (from request_catalogues()) is for an answer made outside the request that
        chose the language: a WebSocket's frames, read on their own thread.
        """
        def render(value: Text) -> str:
            return value.translated(catalogues)

        translated = _lookup(self.msgid, catalogues)
        if translated == self.msgid:
            return _fill(self.msgid, self.values, render)
        try:
            return _fill(translated, self.values, render)
        except (KeyError, ValueError, TypeError):
            # A catalogue whose placeholders do not match the msgid's: the English, and say so.
            log.warning("the translation of %r does not fit its values; answering in English", self.msgid)
            return _fill(self.msgid, self.values, render)

    def wire(self) -> dict:
        """The form a browser translates: {"id": msgid, "values": {...}}, a Text value in its own wire form.

        Sent beside the English as `<field>_i18n` (with_wire), for a sentence pushed to every viewer
        whatever their language; static/js/core/i18n.js's `said` reads it."""
        values = {name: value.wire() if isinstance(value, Text) else value for name, value in self.values.items()}
        return {"id": self.msgid, "values": values} if values else {"id": self.msgid}

    def __repr__(self) -> str:
        return f"Text({self.msgid!r}, {self.values!r})"

    def __reduce__(self):
        return Text, (self.msgid, self.values)


def explain(msgid: str, **values: Any) -> Text:
    """A reason written where it is decided and shown elsewhere (an exception's argument).

    `explain` is an extraction keyword: the msgid must be a literal.
    """
    return Text(msgid, values)


def said(msgid: str, **values: Any) -> Text:
    """A sentence pushed to every viewer (an SSE channel, a state answer), translated in each browser.

    The same Text as explain(), under another extraction keyword: `said` messages go to events.po
    (translations/events_babel.cfg), the catalogue the browser code also receives, so a page in
    Spanish says it in Spanish from the `<field>_i18n` beside the English (with_wire). A Text that is
    a value of a said message is shown in the browser too: write it with `said` as well.
    """
    return Text(msgid, values)


def with_wire(payload: dict) -> dict:
    """`payload` with `<key>_i18n` beside each value that is a Text: the English stays where it was."""
    for key, value in list(payload.items()):
        if isinstance(value, Text):
            payload[f"{key}_i18n"] = value.wire()
    return payload


WIRE_DEPTH = 4  # a sentence within a sentence within...: deeper than the code ever says is not one


def from_wire(wire: Any, english: str) -> str:
    """A sentence received in its wire form (a robot's summary, read on the hub), in the request's language.

    The form came from elsewhere: anything that is not one (a bad id, values that do not fill it,
    too deep) gives the English that was sent beside it, never an error."""
    try:
        return _text_from_wire(wire, 0).translated()
    except (KeyError, ValueError, TypeError):
        return english


def _text_from_wire(wire: Any, depth: int) -> Text:
    if depth > WIRE_DEPTH or not isinstance(wire, dict) or not isinstance(wire.get("id"), str):
        raise ValueError("not a sentence")
    raw = wire.get("values", {})
    if not isinstance(raw, dict):
        raise ValueError("values are not an object")
    values = {}
    for name, value in raw.items():
        if isinstance(value, dict):
            value = _text_from_wire(value, depth + 1)
        elif value is not None and not isinstance(value, str | int | float | bool):
            raise ValueError("a value is neither text nor a number")
        values[str(name)] = value
    return Text(wire["id"], values)


def text_of(exc: BaseException) -> Text:
    """The Text an exception was raised with (its `text`, or an `explain(...)` argument).

    An exception that carries none (a library's) gives its English, untranslated.
    """
    carried = getattr(exc, "text", None)
    if isinstance(carried, Text):
        return carried
    if exc.args and isinstance(exc.args[0], Text):
        return exc.args[0]
    return Text("%(reason)s", {"reason": str(exc)})


def as_text(message: str | Text, values: dict[str, Any]) -> Text:
    if isinstance(message, Text):
        if values:
            return Text(message.msgid, {**message.values, **values})
        return message
    return Text(message, values)


def _fill(msgid: str, values: dict[str, Any], render) -> str:
    if not values:
        return msgid
    rendered = {name: render(value) if isinstance(value, Text) else value for name, value in values.items()}
    return str.__str__(msgid % rendered)


def request_catalogues() -> tuple:
    """The request's language's catalogues, kept by a connection that answers later on another
    thread (teleop's WebSocket and data channel); () when no Babel is set up: English."""
    if not has_request_context() or "babel" not in current_app.extensions:
        return ()
    try:
        # The app's one catalogue (rover_web/i18n folds every .po of a language, api.po included).
        return (get_domain().get_translations(),)
    except Exception:  # noqa: BLE001 - a connection is never refused for its language
        log.warning("the request's catalogues could not be loaded; its answers will be English", exc_info=True)
        return ()


def _lookup(msgid: str, catalogues: tuple | None = None) -> str:
    if catalogues is None:
        if not has_request_context() or "babel" not in current_app.extensions:
            return msgid  # no Babel set up (a tool, a test app), or no request: English
        catalogues = request_catalogues()
    for catalogue in catalogues:
        try:
            translated = catalogue.gettext(msgid)
        except Exception:  # noqa: BLE001 - an unreadable catalogue must never turn an error into a 500
            log.warning("an API message could not be looked up; answering in English", exc_info=True)
            return msgid
        if translated != msgid:
            return translated
    return msgid

