"""No template shows an English word outside `_()`, `ngettext` or `{% trans %}`.

Each template is read with Jinja's own lexer and parser, as the app reads it:
- the HTML between tags (text, and the attributes people read: title, aria-label, placeholder,
  alt...) with every `{{ expression }}` taken out and every `{% trans %}` block left out;
- string constants an expression may output (`{{ 'on' if x else 'off' }}`, a filter's input, a
  dict or list of labels), unless they are the argument of a translation call.
A word is two letters or more. What is not translated on purpose is in KEPT, each with its reason.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

import pytest
from jinja2 import nodes

from rover_web.config import ROOT

TEMPLATES = ROOT / "templates"
GETTEXT = {"_", "gettext", "ngettext", "pgettext", "npgettext"}
# Attributes a person reads or hears (and `value` of a button-like input); data-readonly-reason is
# the sentence the page's scripts show on a control a viewer may not use.
READ_ATTRIBUTES = {"title", "aria-label", "aria-description", "aria-roledescription", "aria-valuetext", "placeholder",
                   "alt", "label", "data-readonly-reason"}
# Element contents that are code, keys or data, never prose (the contract keeps ROS names, key names
# and identifiers untranslated): no word in them is looked at.
VERBATIM = {"code", "kbd", "samp", "script", "style", "pre"}
# Words kept in every language, each for a reason:
KEPT = {
    "rover_web",  # the product's name
    "ROS", "Zenoh", "Nav2", "MCAP", "URDF", "WebRTC", "MJPEG", "Swagger", "UI", "OpenAPI",  # product names
    "TF",  # ROS's name for its transform library, which the page is about
    "WASD",  # key names
    # ROS levels (diagnostic_msgs, rcl_interfaces/Log), as ROS tools show them
    "OK", "WARN", "ERROR", "STALE", "FATAL", "INFO", "DEBUG",
    "QoS",  # ROS's own term, as ros2 topic info shows it
    "NavigateThroughPoses", "NavigateToPose", "FollowWaypoints",  # Nav2's action names, as its docs call them
    "map", "odom",  # REP 105 frame ids where a frame id is meant (a placeholder); prose says "map" inside _()
    "Hz", "ms", "px", "m/s", "rad/s",  # units (SI and CSS symbols)
}
# base.html's blocks that fill an attribute (the SSE channels, the main element's class): names, not text.
ATTRIBUTE_BLOCKS = {"channels", "main_class"}
WORD = re.compile(r"[^\W\d_][\w'’.\-/]*[^\W_]|[^\W\d_]{2,}")
PRINTF = re.compile(r"%(\([a-z_]+\))?[-+ 0#]*\d*(\.\d+)?[sdfeExXgGr%]")


def words(text: str) -> list[str]:
    """The words of `text` a person reads, less printf conversions, paths, identifiers and KEPT."""
    text = PRINTF.sub(" ", text)
    found = []
    for token in text.split():
        if "_" in token and token.strip("().,:;") in KEPT:
            continue
        if re.search(r"[/_=]|^[.#]|\.[a-z]{2,4}$|://", token) and token.strip("().,:;") not in KEPT:
            continue  # a path, a topic, an identifier, a file name or a URL: not prose
        found += [w for w in WORD.findall(token) if w not in KEPT and len(re.sub(r"\W", "", w)) >= 2]
    return found


class _Page(HTMLParser):
    """Collects the words of text and read attributes; `\ue000<n>\ue001` stands for the n-th expression,
    whose shown constants count only where it lands in read text."""

    def __init__(self, expressions: list[list[str]]):
        super().__init__(convert_charrefs=True)
        self.expressions = expressions
        self.found: list[str] = []
        self.open: list[str] = []

    def read(self, text: str) -> None:
        for index in re.findall("\ue000(\\d+)\ue001", text):
            self.found += self.expressions[int(index)]
        self.found += words(re.sub("\ue000\\d+\ue001", " ", text))

    def handle_starttag(self, tag, attrs):
        if tag not in ("br", "img", "input", "meta", "link", "hr", "source", "wbr"):
            self.open.append(tag)
        attributes = dict(attrs)
        for name, value in attrs:
            readable = name in READ_ATTRIBUTES or (tag == "input" and name == "value"
                                                   and attributes.get("type") in ("button", "submit"))
            if readable and value:
                self.read(value)

    def handle_endtag(self, tag):
        if tag in self.open:
            while self.open.pop() != tag:
                pass

    def handle_data(self, data):
        if not VERBATIM & set(self.open):
            self.read(data)


def markup_without_code(env, source: str, macros: set[str]) -> tuple[str, list[list[str]]]:
    """The template's HTML, each expression a numbered placeholder (with the words it may show), and
    trans blocks, tags and comments left out."""
    out, shown, in_trans, attribute_block = [], [], 0, False
    tokens = list(env.lex(source))
    i = 0
    while i < len(tokens):
        _line, kind, value = tokens[i]
        if kind == "block_begin":
            j = i + 1
            while tokens[j][1] == "whitespace":
                j += 1
            if tokens[j][2] == "trans":
                in_trans += 1
            elif tokens[j][2] == "endtrans":
                in_trans -= 1
            elif tokens[j][2] == "block":  # a block that fills an attribute of base.html, not text
                k = j + 1
                while tokens[k][1] == "whitespace":
                    k += 1
                if tokens[k][2] in ATTRIBUTE_BLOCKS:
                    in_trans += 1
                    attribute_block = True
            elif tokens[j][2] == "endblock" and attribute_block:
                in_trans -= 1
                attribute_block = False
            while tokens[i][1] != "block_end":
                i += 1
        elif kind == "variable_begin":
            expression = []
            i += 1
            while tokens[i][1] != "variable_end":
                expression.append(tokens[i][2])
                i += 1
            if not in_trans:
                tree = env.parse("{{ " + "".join(expression) + " }}")
                out.append(f"\ue000{len(shown)}\ue001")
                shown.append(shown_words(next(tree.find_all(nodes.Output)).nodes[0], macros))
        elif kind == "data" and not in_trans:
            out.append(value)
        i += 1
    return "".join(out), shown


def shown_words(node, macros: set[str]) -> list[str]:
    """The words of string constants an expression shows as they are (not inside a translation call)."""
    found = []

    def shown(node):
        if isinstance(node, nodes.Const) and isinstance(node.value, str):
            found.extend(words(node.value))
        elif isinstance(node, nodes.CondExpr):
            shown(node.expr1)
            if node.expr2 is not None:
                shown(node.expr2)
        elif isinstance(node, nodes.Or | nodes.And):
            shown(node.left)
            shown(node.right)
        elif isinstance(node, nodes.Concat):
            for part in node.nodes:
                shown(part)
        elif isinstance(node, nodes.Filter) and node.name not in ("tojson", "urlencode", "e", "safe"):
            shown(node.node)
            if node.name in ("default", "d", "join", "replace"):
                for arg in node.args:
                    shown(arg)
        elif isinstance(node, nodes.List | nodes.Tuple):
            for item in node.items:
                shown(item)
        elif isinstance(node, nodes.Dict):
            for pair in node.items:
                shown(pair.value)
        elif isinstance(node, nodes.Call):
            if isinstance(node.node, nodes.Name) and node.node.name in GETTEXT:
                return
            if isinstance(node.node, nodes.Getattr) and node.node.attr == "get":  # {'a': 'text'}.get(x)
                shown(node.node.node)
                for arg in node.args[1:]:
                    shown(arg)
            elif isinstance(node.node, nodes.Name) and node.node.name in macros:  # the texts a macro is given
                for arg in node.args:
                    shown(arg)
                for kw in node.kwargs:
                    shown(kw.value)
        elif isinstance(node, nodes.Getitem):  # ('a', 'b')[i]
            shown(node.node)

    shown(node)
    return found


def loop_and_set_words(tree, macros: set[str]) -> list[str]:
    """Labels listed in a `{% for %}` or kept with `{% set %}`: shown later through a variable."""
    found = []
    for loop in tree.find_all(nodes.For):  # {% for key, label in [('title', 'robot'), ...] %}
        if isinstance(loop.iter, nodes.List | nodes.Tuple):
            for item in loop.iter.items:
                items = item.items if isinstance(item, nodes.Tuple) else [item]
                for value in items[1:] if len(items) > 1 else items:
                    found += shown_words(value, macros)
    for assign in tree.find_all(nodes.Assign):
        found += shown_words(assign.node, macros)
    return found


def untranslated(env, name: str) -> list[str]:
    source = (TEMPLATES / name).read_text()
    tree = env.parse(source)
    macros = {m.name for m in tree.find_all(nodes.Macro)}
    macros |= {n if isinstance(n, str) else n[1] for i in tree.find_all(nodes.FromImport) for n in i.names}
    markup, expressions = markup_without_code(env, source, macros)
    page = _Page(expressions)
    page.feed(markup)
    page.close()
    return page.found + loop_and_set_words(tree, macros)


def template_names() -> list[str]:
    return sorted(p.relative_to(TEMPLATES).as_posix() for p in TEMPLATES.rglob("*.html"))


@pytest.fixture(scope="module")
def env():
    from jinja2 import Environment

    return Environment(extensions=["jinja2.ext.i18n"])


@pytest.mark.parametrize("name", template_names())
def test_no_untranslated_words(env, name):
    assert untranslated(env, name) == []


def test_the_check_sees_what_it_must(env, tmp_path, monkeypatch):
    """The check itself: each way an English word can hide in a template is found; the translated forms pass."""
    cases = {
        "<p>Drive</p>": ["Drive"],
        '<button title="Stop the robot">{{ _("Stop") }}</button>': ["Stop", "the", "robot"],
        "{{ 'engaged' if on else 'released' }}": ["engaged", "released"],
        "{{ {'green': 'not running'}.get(state) }}": ["not", "running"],
        "{% for k, label in [('a', 'robot')] %}{{ label }}{% endfor %}": ["robot"],
        '<input type="submit" value="Save">': ["Save"],
        "<p>{{ _('Drive') }} <code>cmd_vel</code> {% trans %}Hello{% endtrans %} 5 Hz, E-STOP</p>": ["E-STOP"],
        "<p>{{ ngettext('%(num)d robot', '%(num)d robots', n) }} /cmd_vel rover_web</p>": [],
        "<script>const a = 'not text';</script>": [],
    }
    monkeypatch.setattr(__import__(__name__, fromlist=["TEMPLATES"]), "TEMPLATES", tmp_path)
    for text, expected in cases.items():
        (tmp_path / "t.html").write_text(text)
        assert untranslated(env, "t.html") == expected, text
