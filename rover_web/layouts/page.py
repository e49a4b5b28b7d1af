"""The dashboard's cards and channels from a layout: what the page includes and subscribes to.

Channels come from the cards, so a layout without a camera, a map or a plot never asks the server
for them. A card whose feature did not register its dashboard panel on this robot is left out
(the page says which), rather than rendered empty.
"""

from __future__ import annotations

from dataclasses import dataclass

from rover_web.core.state import Rover

from .cards import CARDS, CardType


@dataclass(frozen=True)
class PlacedCard:
    index: int  # the place in the layout: the order cards stack in on a phone
    kind: CardType
    x: int
    y: int
    w: int
    h: int
    settings: dict

    @property
    def type(self) -> str:
        return self.kind.name


def place(rover: Rover, doc: dict) -> tuple[list[PlacedCard], list[str], list[str]]:
    """The cards this robot can show, the SSE channels they need ("status" first: it is the page's
    heartbeat), and the types left out."""
    panels = {p.template: p for p in rover.dashboard_panels}
    channels = ["status"]
    placed: list[PlacedCard] = []
    missing: list[str] = []
    for i, card in enumerate(doc["cards"]):
        kind = CARDS.get(card["type"])
        if kind is None or (kind.panel and kind.panel not in panels):
            missing.append(card["type"])
            continue
        needed = (panels[kind.panel].channels if kind.panel else ()) + kind.channels
        channels += [c for c in needed if c not in channels]
        placed.append(PlacedCard(i, kind, card["x"], card["y"], card["w"], card["h"], card.get("settings", {})))
    return placed, channels, missing
