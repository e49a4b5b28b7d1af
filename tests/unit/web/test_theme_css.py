"""The themes' style sheet (static/css/app.css): the daylight variables are written twice (the
theme chosen, and "auto" in a light browser) and must stay the same; both themes define the same
variables; no style sheet paints a state colour past the variables."""

import re
from pathlib import Path

CSS = Path(__file__).resolve().parents[3] / "static" / "css"


def _block(text: str, selector: str) -> dict[str, str]:
    start = text.index(selector + " {") + len(selector) + 2
    body = text[start:text.index("}", start)]
    return dict(re.findall(r"(--[\w-]+):\s*([^;]+);", body))


def test_daylight_is_the_same_chosen_or_automatic():
    text = (CSS / "app.css").read_text()
    chosen = _block(text, ':root[data-theme="daylight"]')
    automatic = _block(text, '  :root[data-theme="auto"]')
    assert chosen and chosen == automatic


def test_both_themes_define_the_same_variables():
    text = (CSS / "app.css").read_text()
    dark = _block(text, ':root, :root[data-theme="dark"]')
    daylight = _block(text, ':root[data-theme="daylight"]')
    assert len(dark) > 30 and dark.keys() == daylight.keys()
    assert {k for k in dark if dark[k] == daylight[k]} <= {"--estop-text", "--on-strong"}


def test_the_dark_themes_state_colours_are_only_in_the_variables():
    # The state words' colours of the dark theme (ok, warning, fault): a rule that names one
    # directly would keep it in daylight, light on white.
    for sheet in [*CSS.glob("*.css"), *CSS.glob("dashboard/*.css")]:
        text = sheet.read_text()
        if sheet.name == "app.css":
            text = text[text.index("* { box-sizing"):]
        # (A map legend swatch or marker keeps the colour its map layer is drawn in; text on a
        # ground of its own that is the same in both themes says "either theme".)
        for colour in ("#7ee787", "#e3b341", "#ff7b72"):
            lines = [line for line in text.splitlines()
                     if colour in line and not re.search(r"swatch|vertex|either theme", line)]
            assert lines == [], (sheet.name, colour, lines)
