"""Control panels defined in a TOML file: loaded once at start, every mistake named precisely.

A panel is a set of status displays (a field of a subscribed topic), buttons (a fixed value
published on a topic) and inputs (an operator-chosen value published on a topic), plus the rules
saying in which displayed states each control may be used. Commands are std_msgs scalars or
std_msgs/String; displays may read a field of any message type. Pure Python: message fields are
checked through the `field_kind` callable the caller passes (rover_web.panels.msgs.field_kind).

Every error is a ConfigError reading "<file>: panel 'p', control 'c', field 'f': <what is wrong>",
so the operator can fix the file without reading code.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from rover_web.config import ConfigError

from .file_fields import (
    ID_RE,
    Where,
    bool_field,
    bound_field,
    check_id,
    only_keys,
    positive_field,
    sub_tables,
    text_field,
    topic_field,
    type_field,
)
from .scalars import MAX_STRING_LENGTH, SCALAR_TYPES, InvalidValue, ScalarType, coerce, describe, number_text

DEFAULT_FILE = Path(__file__).with_name("drone.toml")
# Path segments under /api/panels/<panel>/ that are not controls.
RESERVED_CONTROL_IDS = frozenset({"unlock", "lock", "log"})
QOS_NAMES = ("default", "sensor_data", "latched")
STYLES = ("", "primary", "danger")
DEFAULT_UNLOCK_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class DisplaySpec:
    id: str
    label: str
    topic: str
    type: str          # canonical message type
    field: str         # dotted path into the message; "" shows the whole message
    qos: str = "default"
    unit: str = ""
    digits: int = 2    # decimals shown for floating-point values
    kind: str = "other"  # what the field holds: string | int | float | bool | message | other


@dataclass(frozen=True)
class ControlSpec:
    id: str
    kind: str          # button | input
    label: str
    topic: str
    type: ScalarType
    value: Any = None  # buttons: what they publish
    low: float | None = None   # inputs: accepted range (defaults to the type's)
    high: float | None = None
    max_length: int = 256      # String inputs
    action: str = ""           # inputs: the label of the button that sends the value
    enabled_when: tuple[tuple[str, tuple[Any, ...]], ...] = ()
    confirm: bool = False
    requires_unlock: bool = True
    style: str = ""
    allowed_during_estop: bool = False  # may still be sent while the e-stop is engaged (a "stop" or "land")


@dataclass(frozen=True)
class LightSpec:
    """Green while `display` shows one of `idle` (no mission running), red for any other value."""

    display: str
    idle: tuple[Any, ...]
    label: str = "Mission"


@dataclass(frozen=True)
class PanelSpec:
    id: str
    title: str
    displays: tuple[DisplaySpec, ...]
    controls: tuple[ControlSpec, ...]
    light: LightSpec | None
    unlock_timeout_s: float
    stale_after_s: float
    on_estop: str | None = None  # a button sent automatically when the e-stop engages (no unlock needed)

    def display(self, display_id: str) -> DisplaySpec | None:
        return next((d for d in self.displays if d.id == display_id), None)

    def control(self, control_id: str) -> ControlSpec | None:
        return next((c for c in self.controls if c.id == control_id), None)

    def resolved(self, resolve: Callable[[str], str]) -> PanelSpec:
        """This panel with its topics under a robot's namespace (rover.resolve)."""
        return replace(self, displays=tuple(replace(d, topic=resolve(d.topic)) for d in self.displays),
                       controls=tuple(replace(c, topic=resolve(c.topic)) for c in self.controls))


FieldKind = Callable[[str, str], str]  # (message type, field path) -> kind; ValueError if no such field


def load(path: str | Path | None, stale_after_s: float, field_kind: FieldKind | None = None) -> tuple[PanelSpec, ...]:
    """Read and validate the panel file (the shipped drone panel when `path` is None)."""
    path = Path(path) if path else DEFAULT_FILE
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except OSError as exc:
        raise ConfigError(f"ROVER_WEB_PANELS_FILE: cannot read {path}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    return parse(data, str(path), stale_after_s, field_kind)


def parse(data: dict, path: str, stale_after_s: float, field_kind: FieldKind | None = None) -> tuple[PanelSpec, ...]:
    where = Where(path)
    only_keys(data, {"panels"}, where, "top level")
    panels = data.get("panels")
    if not isinstance(panels, dict) or not panels:
        raise where.error("defines no panels; add a table such as [panels.drone]")
    specs = tuple(_panel(pid, table, Where(path, pid), stale_after_s, field_kind) for pid, table in panels.items())
    _check_topic_types(specs, where)
    return specs


def _panel(pid: str, table: Any, where: Where, default_stale_s: float, field_kind: FieldKind | None) -> PanelSpec:
    if not ID_RE.match(pid):
        raise where.error("panel ids are 1-32 lower-case letters, digits, '-' or '_', starting with a letter "
                          "(they appear in URLs)")
    if not isinstance(table, dict):
        raise where.error("must be a table of fields, e.g. [panels.drone]")
    only_keys(table, {"title", "unlock_timeout_s", "stale_after_s", "light", "displays", "controls", "on_estop"},
               where, None)
    title = text_field(table, "title", where, default=pid.replace("_", " ").capitalize())
    unlock_timeout_s = positive_field(table, "unlock_timeout_s", where, DEFAULT_UNLOCK_TIMEOUT_S)
    stale_after_s = positive_field(table, "stale_after_s", where, default_stale_s)

    displays_table = sub_tables(table, "displays", where)
    displays = tuple(_display(did, d, where.at(f"display '{did}'"), field_kind) for did, d in displays_table.items())
    by_id = {d.id: d for d in displays}

    controls_table = sub_tables(table, "controls", where)
    if not controls_table and not displays_table:
        raise where.error("has no displays and no controls; add [panels.<id>.displays.<id>] or "
                          "[panels.<id>.controls.<id>] tables")
    controls = tuple(_control(cid, c, where.at(f"control '{cid}'"), by_id) for cid, c in controls_table.items())

    light = None
    if "light" in table:
        light = _light(table["light"], where.at("light"), by_id)
    on_estop = None
    if "on_estop" in table:
        on_estop = text_field(table, "on_estop", where)
        control = next((c for c in controls if c.id == on_estop), None)
        if control is None or control.kind != "button":
            buttons = ", ".join(c.id for c in controls if c.kind == "button") or "none"
            raise where.error(f"names {on_estop!r}, which is not a button of this panel (buttons: {buttons})",
                              "on_estop")
    return PanelSpec(pid, title, displays, controls, light, unlock_timeout_s, stale_after_s, on_estop)


def _display(did: str, d: Any, where: Where, field_kind: FieldKind | None) -> DisplaySpec:
    check_id(did, where)
    if not isinstance(d, dict):
        raise where.error("must be a table of fields (label, topic, type, field)")
    only_keys(d, {"label", "topic", "type", "field", "qos", "unit", "digits"}, where, None)
    label = text_field(d, "label", where)
    topic = topic_field(d, where)
    type_name = type_field(d, where)
    field = text_field(d, "field", where, default="data", allow_empty=True)
    qos = text_field(d, "qos", where, default="default")
    if qos not in QOS_NAMES:
        raise where.error(f"must be one of {', '.join(QOS_NAMES)}, got {qos!r}", "qos")
    unit = text_field(d, "unit", where, default="", allow_empty=True)
    digits = d.get("digits", 2)
    if isinstance(digits, bool) or not isinstance(digits, int) or not 0 <= digits <= 9:
        raise where.error(f"must be an integer from 0 to 9, got {describe(digits)}", "digits")
    kind = "other"
    if field_kind is not None:
        try:
            kind = field_kind(type_name, field)
        except LookupError as exc:  # the message type is not installed or not a message
            raise where.error(str(exc), "type") from None
        except ValueError as exc:
            raise where.error(str(exc), "field") from None
    elif type_name in SCALAR_TYPES and field == "data":
        kind = SCALAR_TYPES[type_name].kind
    return DisplaySpec(did, label, topic, type_name, field, qos, unit, digits, kind)


def _control(cid: str, c: Any, where: Where, displays: dict[str, DisplaySpec]) -> ControlSpec:
    check_id(cid, where)
    if cid in RESERVED_CONTROL_IDS:
        raise where.error(f"'{cid}' is reserved (/api/panels/<panel>/{cid} is not a control); choose another id")
    if not isinstance(c, dict):
        raise where.error("must be a table of fields (kind, label, topic, type, ...)")
    kind = c.get("kind")
    if kind not in ("button", "input"):
        raise where.error(f"must be \"button\" or \"input\", got {describe(kind)}", "kind")
    common = {"kind", "label", "topic", "type", "enabled_when", "confirm", "requires_unlock", "style",
              "allowed_during_estop"}
    extra = {"value"} if kind == "button" else {"min", "max", "max_length", "action"}
    only_keys(c, common | extra, where, "a button" if kind == "button" else "an input")
    label = text_field(c, "label", where)
    topic = topic_field(c, where)
    type_name = type_field(c, where)
    stype = SCALAR_TYPES.get(type_name)
    if stype is None:
        names = ", ".join(sorted(t.split("/")[-1] for t in SCALAR_TYPES))
        raise where.error(f"controls publish a std_msgs scalar ({names}); {type_name} is not one", "type")
    fields: dict[str, Any] = {}
    if kind == "button":
        if "value" not in c:
            raise where.error(f"a button needs the value it publishes on {topic}", "value")
        try:
            fields["value"] = coerce(stype, c["value"])
        except InvalidValue as exc:
            raise where.error(str(exc), "value") from None
    else:
        fields["action"] = text_field(c, "action", where, default="Send")
        if stype.kind in ("int", "float"):
            low = bound_field(c, "min", stype, where, stype.low)
            high = bound_field(c, "max", stype, where, stype.high)
            if low > high:
                raise where.error(f"min ({number_text(low)}) is greater than max ({number_text(high)})", "min")
            fields["low"], fields["high"] = low, high
        else:
            for key in ("min", "max"):
                if key in c:
                    raise where.error(f"{stype.short} has no numeric range; remove '{key}'", key)
        if stype.kind == "string":
            max_length = c.get("max_length", 256)
            if isinstance(max_length, bool) or not isinstance(max_length, int) \
                    or not 1 <= max_length <= MAX_STRING_LENGTH:
                raise where.error(f"must be an integer from 1 to {MAX_STRING_LENGTH}, got {describe(max_length)}",
                                  "max_length")
            fields["max_length"] = max_length
        elif "max_length" in c:
            raise where.error("only std_msgs/String inputs have a length; remove 'max_length'", "max_length")
    enabled_when = _enabled_when(c.get("enabled_when", {}), where, displays)
    confirm = bool_field(c, "confirm", where, False)
    requires_unlock = bool_field(c, "requires_unlock", where, True)
    allowed_during_estop = bool_field(c, "allowed_during_estop", where, False)
    style = text_field(c, "style", where, default="", allow_empty=True)
    if style not in STYLES:
        raise where.error(f"must be \"primary\", \"danger\" or empty, got {style!r}", "style")
    return ControlSpec(cid, kind, label, topic, stype, enabled_when=enabled_when, confirm=confirm,
                       requires_unlock=requires_unlock, style=style, allowed_during_estop=allowed_during_estop,
                       **fields)


def _enabled_when(rules: Any, where: Where, displays: dict[str, DisplaySpec]):
    if not isinstance(rules, dict):
        raise where.error("must be a table of display id = [allowed values], e.g. { status = [\"Standby\"] }",
                          "enabled_when")
    out = []
    for did, allowed in rules.items():
        display = displays.get(did)
        if display is None:
            raise where.error(f"names display '{did}', which this panel does not have "
                              f"(displays: {', '.join(displays) or 'none'})", "enabled_when")
        out.append((did, _values(allowed, display, where, f"enabled_when.{did}")))
    return tuple(out)


def _light(light: Any, where: Where, displays: dict[str, DisplaySpec]) -> LightSpec:
    if not isinstance(light, dict):
        raise where.error("must be a table: { display = \"status\", idle = [\"Standby\"] }")
    only_keys(light, {"display", "idle", "label"}, where, None)
    did = text_field(light, "display", where)
    display = displays.get(did)
    if display is None:
        raise where.error(f"names display '{did}', which this panel does not have "
                          f"(displays: {', '.join(displays) or 'none'})", "display")
    if "idle" not in light:
        raise where.error("list the values that mean no mission is running, e.g. [\"Standby\"]", "idle")
    idle = _values(light["idle"], display, where, "idle")
    return LightSpec(did, idle, text_field(light, "label", where, default="Mission"))


_VALUE_TYPES = {"string": (str,), "int": (int,), "float": (int, float), "bool": (bool,)}


def _values(allowed: Any, display: DisplaySpec, where: Where, field: str) -> tuple[Any, ...]:
    if not isinstance(allowed, list) or not allowed:
        raise where.error(f"must be a non-empty list of values of display '{display.id}', got {describe(allowed)}",
                          field)
    expected = _VALUE_TYPES.get(display.kind)
    for value in allowed:
        if isinstance(value, (dict, list)) or not isinstance(value, (str, int, float, bool)):
            raise where.error(f"values must be strings, numbers or booleans, got {describe(value)}", field)
        if expected and (not isinstance(value, expected) or display.kind != "bool" and isinstance(value, bool)):
            raise where.error(f"display '{display.id}' shows {display.kind} values ({display.type} "
                              f"{display.field or 'message'}), so {describe(value)} can never match", field)
    return tuple(allowed)


def _check_topic_types(specs: tuple[PanelSpec, ...], where: Where) -> None:
    """One topic, one type: DDS would never match a publisher and subscriber that disagree."""
    seen: dict[str, tuple[str, str]] = {}
    for panel in specs:
        items = [(d.topic, d.type, f"panel '{panel.id}', display '{d.id}'") for d in panel.displays]
        items += [(c.topic, c.type.name, f"panel '{panel.id}', control '{c.id}'") for c in panel.controls]
        for topic, type_name, what in items:
            first = seen.setdefault(topic, (type_name, what))
            if first[0] != type_name:
                raise ConfigError(f"{where.path}: {what}, field 'type': {topic} is {first[0]} in {first[1]} "
                                  f"but {type_name} here; one topic carries one type")
    qos_seen: dict[str, tuple[str, str]] = {}
    for panel in specs:
        for d in panel.displays:
            first = qos_seen.setdefault(d.topic, (d.qos, f"panel '{panel.id}', display '{d.id}'"))
            if first[0] != d.qos:
                raise ConfigError(f"{where.path}: panel '{panel.id}', display '{d.id}', field 'qos': {d.topic} is "
                                  f"read with qos {first[0]!r} in {first[1]} but {d.qos!r} here; the app "
                                  f"subscribes once per topic")

