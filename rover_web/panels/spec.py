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

import math
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from rover_web.config import TOPIC_PATTERN, ConfigError

DEFAULT_FILE = Path(__file__).with_name("drone.toml")
ID_RE = re.compile(r"[a-z][a-z0-9_-]{0,31}\Z")
# Path segments under /api/panels/<panel>/ that are not controls.
RESERVED_CONTROL_IDS = frozenset({"unlock", "lock", "log"})
QOS_NAMES = ("default", "sensor_data", "latched")
STYLES = ("", "primary", "danger")
DEFAULT_UNLOCK_TIMEOUT_S = 60.0
MAX_STRING_LENGTH = 1024

FLOAT32_MAX = 3.4028234663852886e38
FLOAT64_MAX = 1.7976931348623157e308


@dataclass(frozen=True)
class ScalarType:
    """A std_msgs message with one `data` field: what JSON values it takes and their range."""

    name: str  # canonical, "std_msgs/msg/Int8"
    kind: str  # int | float | bool | string
    low: float | None = None
    high: float | None = None

    @property
    def short(self) -> str:
        return self.name.replace("/msg/", "/")


def _int(name: str, bits: int, signed: bool) -> ScalarType:
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return ScalarType(f"std_msgs/msg/{name}", "int", low, high)


SCALAR_TYPES: dict[str, ScalarType] = {t.name: t for t in (
    ScalarType("std_msgs/msg/Bool", "bool"),
    _int("Byte", 8, False),   # octet: one byte, sent as 0..255
    _int("Char", 8, False),   # ROS 2 char is an unsigned 8-bit integer
    _int("Int8", 8, True), _int("UInt8", 8, False),
    _int("Int16", 16, True), _int("UInt16", 16, False),
    _int("Int32", 32, True), _int("UInt32", 32, False),
    _int("Int64", 64, True), _int("UInt64", 64, False),
    ScalarType("std_msgs/msg/Float32", "float", -FLOAT32_MAX, FLOAT32_MAX),
    ScalarType("std_msgs/msg/Float64", "float", -FLOAT64_MAX, FLOAT64_MAX),
    ScalarType("std_msgs/msg/String", "string"),
)}

_TYPE_NAME_RE = re.compile(r"([a-z][a-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)\Z")


def canonical_type(name: str) -> str | None:
    """"std_msgs/Int8" and "std_msgs/msg/Int8" both become "std_msgs/msg/Int8"; None if malformed."""
    match = _TYPE_NAME_RE.match(name) if isinstance(name, str) else None
    return f"{match.group(1)}/msg/{match.group(2)}" if match else None


class InvalidValue(ValueError):
    """A value a control cannot publish; `code` is the API's short reason."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code


def coerce(stype: ScalarType, value: Any, *, low: float | None = None, high: float | None = None,
           max_length: int = MAX_STRING_LENGTH) -> Any:
    """The value as the message field wants it, or InvalidValue saying why it cannot be sent."""
    low = stype.low if low is None else low
    high = stype.high if high is None else high
    if stype.kind == "bool":
        if not isinstance(value, bool):
            raise InvalidValue(f"must be true or false for {stype.short}, got {_describe(value)}", "bad_type")
        return value
    if stype.kind == "string":
        if not isinstance(value, str):
            raise InvalidValue(f"must be a string for {stype.short}, got {_describe(value)}", "bad_type")
        if len(value) > max_length:
            raise InvalidValue(f"must be at most {max_length} characters, got {len(value)}", "too_long")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        expected = "an integer" if stype.kind == "int" else "a number"
        raise InvalidValue(f"must be {expected} for {stype.short}, got {_describe(value)}", "bad_type")
    if isinstance(value, float) and not math.isfinite(value):
        raise InvalidValue(f"must be a finite number, got {value}", "non_finite")
    if stype.kind == "int":
        if isinstance(value, float):
            if not value.is_integer():
                raise InvalidValue(f"must be an integer for {stype.short}, got {value:g}", "bad_type")
            value = int(value)
    if value < low or value > high:  # before float(): an integer of hundreds of digits overflows it
        huge = isinstance(value, int) and abs(value) >= 10 ** 30
        shown = f"an integer of {len(str(abs(value)))} digits" if huge else _num(value)
        raise InvalidValue(f"must be from {_num(low)} to {_num(high)} for {stype.short}, got {shown}",
                           "out_of_range")
    return value if stype.kind == "int" else float(value)


def _num(value: float) -> str:
    return str(value) if isinstance(value, int) else f"{value:g}"


def _describe(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"the string {value[:40]!r}"
    if isinstance(value, (int, float)):
        return _num(value)
    if value == []:
        return "an empty list"
    return {dict: "an object", list: "a list", type(None): "null"}.get(type(value), type(value).__name__)


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


class _Where:
    """Builds error messages that name the file, panel, item and field."""

    def __init__(self, path: str, panel: str | None = None, item: str | None = None):
        self.path, self.panel, self.item = path, panel, item

    def at(self, item: str) -> _Where:
        return _Where(self.path, self.panel, item)

    def error(self, problem: str, field: str | None = None) -> ConfigError:
        parts = []
        if self.panel is not None:
            parts.append(f"panel '{self.panel}'")
        if self.item is not None:
            parts.append(self.item)
        if field is not None:
            parts.append(f"field '{field}'")
        where = ", ".join(parts)
        return ConfigError(f"{self.path}: {where + ': ' if where else ''}{problem}")


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
    where = _Where(path)
    _only_keys(data, {"panels"}, where, "top level")
    panels = data.get("panels")
    if not isinstance(panels, dict) or not panels:
        raise where.error("defines no panels; add a table such as [panels.drone]")
    specs = tuple(_panel(pid, table, _Where(path, pid), stale_after_s, field_kind) for pid, table in panels.items())
    _check_topic_types(specs, where)
    return specs


def _panel(pid: str, table: Any, where: _Where, default_stale_s: float, field_kind: FieldKind | None) -> PanelSpec:
    if not ID_RE.match(pid):
        raise where.error("panel ids are 1-32 lower-case letters, digits, '-' or '_', starting with a letter "
                          "(they appear in URLs)")
    if not isinstance(table, dict):
        raise where.error("must be a table of fields, e.g. [panels.drone]")
    _only_keys(table, {"title", "unlock_timeout_s", "stale_after_s", "light", "displays", "controls", "on_estop"},
               where, None)
    title = _text(table, "title", where, default=pid.replace("_", " ").capitalize())
    unlock_timeout_s = _positive(table, "unlock_timeout_s", where, DEFAULT_UNLOCK_TIMEOUT_S)
    stale_after_s = _positive(table, "stale_after_s", where, default_stale_s)

    displays_table = _table(table, "displays", where)
    displays = tuple(_display(did, d, where.at(f"display '{did}'"), field_kind) for did, d in displays_table.items())
    by_id = {d.id: d for d in displays}

    controls_table = _table(table, "controls", where)
    if not controls_table and not displays_table:
        raise where.error("has no displays and no controls; add [panels.<id>.displays.<id>] or "
                          "[panels.<id>.controls.<id>] tables")
    controls = tuple(_control(cid, c, where.at(f"control '{cid}'"), by_id) for cid, c in controls_table.items())

    light = None
    if "light" in table:
        light = _light(table["light"], where.at("light"), by_id)
    on_estop = None
    if "on_estop" in table:
        on_estop = _text(table, "on_estop", where)
        control = next((c for c in controls if c.id == on_estop), None)
        if control is None or control.kind != "button":
            buttons = ", ".join(c.id for c in controls if c.kind == "button") or "none"
            raise where.error(f"names {on_estop!r}, which is not a button of this panel (buttons: {buttons})",
                              "on_estop")
    return PanelSpec(pid, title, displays, controls, light, unlock_timeout_s, stale_after_s, on_estop)


def _display(did: str, d: Any, where: _Where, field_kind: FieldKind | None) -> DisplaySpec:
    _check_id(did, where)
    if not isinstance(d, dict):
        raise where.error("must be a table of fields (label, topic, type, field)")
    _only_keys(d, {"label", "topic", "type", "field", "qos", "unit", "digits"}, where, None)
    label = _text(d, "label", where)
    topic = _topic(d, where)
    type_name = _message_type(d, where)
    field = _text(d, "field", where, default="data", allow_empty=True)
    qos = _text(d, "qos", where, default="default")
    if qos not in QOS_NAMES:
        raise where.error(f"must be one of {', '.join(QOS_NAMES)}, got {qos!r}", "qos")
    unit = _text(d, "unit", where, default="", allow_empty=True)
    digits = d.get("digits", 2)
    if isinstance(digits, bool) or not isinstance(digits, int) or not 0 <= digits <= 9:
        raise where.error(f"must be an integer from 0 to 9, got {_describe(digits)}", "digits")
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


def _control(cid: str, c: Any, where: _Where, displays: dict[str, DisplaySpec]) -> ControlSpec:
    _check_id(cid, where)
    if cid in RESERVED_CONTROL_IDS:
        raise where.error(f"'{cid}' is reserved (/api/panels/<panel>/{cid} is not a control); choose another id")
    if not isinstance(c, dict):
        raise where.error("must be a table of fields (kind, label, topic, type, ...)")
    kind = c.get("kind")
    if kind not in ("button", "input"):
        raise where.error(f"must be \"button\" or \"input\", got {_describe(kind)}", "kind")
    common = {"kind", "label", "topic", "type", "enabled_when", "confirm", "requires_unlock", "style",
              "allowed_during_estop"}
    extra = {"value"} if kind == "button" else {"min", "max", "max_length", "action"}
    _only_keys(c, common | extra, where, "a button" if kind == "button" else "an input")
    label = _text(c, "label", where)
    topic = _topic(c, where)
    type_name = _message_type(c, where)
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
        fields["action"] = _text(c, "action", where, default="Send")
        if stype.kind in ("int", "float"):
            low = _bound(c, "min", stype, where, stype.low)
            high = _bound(c, "max", stype, where, stype.high)
            if low > high:
                raise where.error(f"min ({_num(low)}) is greater than max ({_num(high)})", "min")
            fields["low"], fields["high"] = low, high
        else:
            for key in ("min", "max"):
                if key in c:
                    raise where.error(f"{stype.short} has no numeric range; remove '{key}'", key)
        if stype.kind == "string":
            max_length = c.get("max_length", 256)
            if isinstance(max_length, bool) or not isinstance(max_length, int) \
                    or not 1 <= max_length <= MAX_STRING_LENGTH:
                raise where.error(f"must be an integer from 1 to {MAX_STRING_LENGTH}, got {_describe(max_length)}",
                                  "max_length")
            fields["max_length"] = max_length
        elif "max_length" in c:
            raise where.error("only std_msgs/String inputs have a length; remove 'max_length'", "max_length")
    enabled_when = _enabled_when(c.get("enabled_when", {}), where, displays)
    confirm = _bool(c, "confirm", where, False)
    requires_unlock = _bool(c, "requires_unlock", where, True)
    allowed_during_estop = _bool(c, "allowed_during_estop", where, False)
    style = _text(c, "style", where, default="", allow_empty=True)
    if style not in STYLES:
        raise where.error(f"must be \"primary\", \"danger\" or empty, got {style!r}", "style")
    return ControlSpec(cid, kind, label, topic, stype, enabled_when=enabled_when, confirm=confirm,
                       requires_unlock=requires_unlock, style=style, allowed_during_estop=allowed_during_estop,
                       **fields)


def _enabled_when(rules: Any, where: _Where, displays: dict[str, DisplaySpec]):
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


def _light(light: Any, where: _Where, displays: dict[str, DisplaySpec]) -> LightSpec:
    if not isinstance(light, dict):
        raise where.error("must be a table: { display = \"status\", idle = [\"Standby\"] }")
    _only_keys(light, {"display", "idle", "label"}, where, None)
    did = _text(light, "display", where)
    display = displays.get(did)
    if display is None:
        raise where.error(f"names display '{did}', which this panel does not have "
                          f"(displays: {', '.join(displays) or 'none'})", "display")
    if "idle" not in light:
        raise where.error("list the values that mean no mission is running, e.g. [\"Standby\"]", "idle")
    idle = _values(light["idle"], display, where, "idle")
    return LightSpec(did, idle, _text(light, "label", where, default="Mission"))


_VALUE_TYPES = {"string": (str,), "int": (int,), "float": (int, float), "bool": (bool,)}


def _values(allowed: Any, display: DisplaySpec, where: _Where, field: str) -> tuple[Any, ...]:
    if not isinstance(allowed, list) or not allowed:
        raise where.error(f"must be a non-empty list of values of display '{display.id}', got {_describe(allowed)}",
                          field)
    expected = _VALUE_TYPES.get(display.kind)
    for value in allowed:
        if isinstance(value, (dict, list)) or not isinstance(value, (str, int, float, bool)):
            raise where.error(f"values must be strings, numbers or booleans, got {_describe(value)}", field)
        if expected and (not isinstance(value, expected) or display.kind != "bool" and isinstance(value, bool)):
            raise where.error(f"display '{display.id}' shows {display.kind} values ({display.type} "
                              f"{display.field or 'message'}), so {_describe(value)} can never match", field)
    return tuple(allowed)


def _check_topic_types(specs: tuple[PanelSpec, ...], where: _Where) -> None:
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


# --- field helpers ---

def _only_keys(table: dict, allowed: set[str], where: _Where, what: str | None) -> None:
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise where.error(f"unknown field{'s' if len(unknown) > 1 else ''} {', '.join(repr(k) for k in unknown)}"
                          f"{' in ' + what if what else ''}; expected {', '.join(sorted(allowed))}")


def _check_id(item_id: str, where: _Where) -> None:
    if not ID_RE.match(item_id):
        raise where.error("ids are 1-32 lower-case letters, digits, '-' or '_', starting with a letter")


def _table(table: dict, key: str, where: _Where) -> dict:
    value = table.get(key, {})
    if not isinstance(value, dict):
        raise where.error(f"must be tables such as [panels.{where.panel}.{key}.<id>], got {_describe(value)}", key)
    return value


def _text(table: dict, key: str, where: _Where, default: Any = ..., allow_empty: bool = False) -> str:
    if key not in table:
        if default is ...:
            raise where.error("is required", key)
        return default
    value = table[key]
    if not isinstance(value, str) or (not value.strip() and not allow_empty):
        raise where.error(f"must be a non-empty string, got {_describe(value)}", key)
    if len(value) > 200:
        raise where.error("is longer than 200 characters", key)
    return value


def _topic(table: dict, where: _Where) -> str:
    topic = _text(table, "topic", where)
    if not TOPIC_PATTERN.match(topic):
        raise where.error(f"{topic!r} is not a ROS topic name such as /control_phase", "topic")
    return topic if topic.startswith(("/", "~")) else "/" + topic


def _message_type(table: dict, where: _Where) -> str:
    raw = _text(table, "type", where)
    name = canonical_type(raw)
    if name is None:
        raise where.error(f"{raw!r} is not a message type such as std_msgs/msg/Int8", "type")
    return name


def _positive(table: dict, key: str, where: _Where, default: float) -> float:
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise where.error(f"must be a positive number of seconds, got {_describe(value)}", key)
    return float(value)


def _bool(table: dict, key: str, where: _Where, default: bool) -> bool:
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise where.error(f"must be true or false, got {_describe(value)}", key)
    return value


def _bound(table: dict, key: str, stype: ScalarType, where: _Where, default: float) -> float:
    if key not in table:
        return default
    try:
        return coerce(stype, table[key])
    except InvalidValue as exc:
        raise where.error(str(exc), key) from None
