// The layout being edited, and its undo history. Pure: no DOM, so it can be checked on its own.
// Every change goes through change(), which keeps the state before it; undo() goes back one.
// Cards carry a transient key (k) that ties them to the editor's tiles; it is never saved.

export const COLUMNS = 12;

let nextKey = 1;
const keyed = (card) => ({ ...card, settings: { ...(card.settings || {}) }, k: nextKey++ });
const clone = (value) => JSON.parse(JSON.stringify(value));

export class LayoutModel {
  constructor(doc, types) {
    this.name = doc.name;
    this.cards = doc.cards.map(keyed);
    this.types = new Map(types.map((t) => [t.name, t]));
    this.history = [];
  }

  snapshot() { return { name: this.name, cards: clone(this.cards) }; }

  change(fn) {
    this.history.push(this.snapshot());
    fn(this);
  }

  undo() {
    const last = this.history.pop();
    if (!last) return false;
    this.name = last.name;
    this.cards = last.cards;
    return true;
  }

  byKey(k) { return this.cards.find((c) => c.k === k); }

  bottom() { return this.cards.reduce((most, c) => Math.max(most, c.y + c.h), 0); }

  // The first cell, in reading order, where a w×h card overlaps nothing: a new card fills the
  // space beside the others before it goes below them.
  firstFree(w, h) {
    const free = (x, y) => this.cards.every((c) => x + w <= c.x || c.x + c.w <= x || y + h <= c.y || c.y + c.h <= y);
    for (let y = 0; y <= this.bottom(); y++) {
      for (let x = 0; x + w <= COLUMNS; x++) if (free(x, y)) return { x, y };
    }
    return { x: 0, y: this.bottom() };
  }

  // A new card of `type` at its default size in the first free place; null when the layout holds
  // one already and the type may appear once.
  add(type, settings = {}) {
    const t = this.types.get(type);
    if (!t || (t.once && this.cards.some((c) => c.type === type))) return null;
    const w = Math.min(COLUMNS, t.size[0]);
    const card = keyed({ type, ...this.firstFree(w, t.size[1]), w, h: t.size[1], settings });
    this.change((m) => { m.cards.push(card); m.cards.sort((a, b) => a.y - b.y || a.x - b.x); });
    return card;
  }

  clear() { if (this.cards.length) this.change((m) => { m.cards = []; }); }

  remove(k) { this.change((m) => { m.cards = m.cards.filter((c) => c.k !== k); }); }

  // One place up or down in the layout's order: the order cards stack in on a phone.
  shift(k, by) {
    const i = this.cards.findIndex((c) => c.k === k);
    const j = i + by;
    if (i < 0 || j < 0 || j >= this.cards.length) return false;
    this.change((m) => { [m.cards[i], m.cards[j]] = [m.cards[j], m.cards[i]]; });
    return true;
  }

  // Cells from the grid editor, {k: {x, y, w, h}}; the order becomes reading order (rows, then
  // columns), which is how a desktop user reads the layout and so how a phone stacks it.
  place(cells) {
    const moved = Object.entries(cells).some(([k, p]) => {
      const c = this.byKey(Number(k));
      return c && (c.x !== p.x || c.y !== p.y || c.w !== p.w || c.h !== p.h);
    });
    if (!moved) return false;
    this.change((m) => {
      for (const [k, p] of Object.entries(cells)) Object.assign(m.byKey(Number(k)) || {}, p);
      m.cards.sort((a, b) => a.y - b.y || a.x - b.x);
    });
    return true;
  }

  setSettings(k, settings) { this.change((m) => { m.byKey(k).settings = settings; }); }

  rename(name) { if (name !== this.name) this.change((m) => { m.name = name; }); }

  // The document the REST API takes (rover_web/layouts/schema.py).
  toDoc() {
    return { version: 1, name: this.name, cards: this.cards.map(({ k, ...card }) => card) };
  }
}
