// The browser code's translations and locale formatting: the same gettext catalogue as the pages
// (docs/i18n_browser.md). Message ids are the English text with Python-format named placeholders,
// `_('Goal sent to %(map)s', { map })`, so one catalogue serves Jinja, Python and this code.
//
// The server names the page's catalogue on <html data-catalogue="URL"> (a hashed, immutable JSON
// file: {"locale", "messages": {msgid: msgstr}, "plurals": {singular: [forms]}}); an English page has
// none, and then nothing here waits on anything. A catalogue that cannot be loaded leaves the page in
// English: a page that cannot say "ENGAGED" in Japanese must still stop the robot.

const root = typeof document !== 'undefined' ? document.documentElement : null;

// The page's language as the server chose it (<html lang>), checked so a bad tag never throws later.
function pageLocale() {
  const tag = (root && root.lang) || 'en';
  try { return Intl.getCanonicalLocales(tag)[0] || 'en'; } catch { return 'en'; }
}

export const locale = pageLocale();

// The browser does not hold DOMContentLoaded for a module's top-level await: it can fire while
// the catalogue is on its way, before the modules that import this one ran. Noted here, before the
// await, for code that must run once every module of the page has (afterPageScripts).
let contentLoaded = !root || document.readyState === 'complete';
if (!contentLoaded) document.addEventListener('DOMContentLoaded', () => { contentLoaded = true; }, { once: true });

// fn once every module script of the page ran: at DOMContentLoaded, or, when that passed while the
// catalogue loaded, right after the modules that waited for it (they all resume together).
export function afterPageScripts(fn) {
  if (contentLoaded) setTimeout(fn, 0);
  else document.addEventListener('DOMContentLoaded', fn, { once: true });
}

const CATALOGUE_WAIT_MS = 8000;  // a 25 kB file (7 kB compressed): seconds even on a poor radio link
let messages = {};
let plurals = {};

const url = root && root.dataset ? root.dataset.catalogue : '';
if (url) {
  // Top-level await: every module that imports this one waits for the catalogue, so no string is
  // ever drawn in English first. Only a translated page pays this one (cached, immutable) fetch.
  // A stalled fetch must not hold the page's modules for ever: past CATALOGUE_WAIT_MS the page goes on
  // in English (the e-stop is a plain form until its module runs, so it works all along).
  const abort = new AbortController();
  const timer = setTimeout(() => abort.abort(new Error(`no answer in ${CATALOGUE_WAIT_MS} ms`)), CATALOGUE_WAIT_MS);
  try {
    const response = await fetch(url, { credentials: 'same-origin', signal: abort.signal });
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    const catalogue = await response.json();
    messages = (catalogue && typeof catalogue.messages === 'object' && catalogue.messages) || {};
    plurals = (catalogue && typeof catalogue.plurals === 'object' && catalogue.plurals) || {};
  } catch (err) {
    console.error(`i18n: the ${locale} catalogue ${url} could not be loaded; the page stays in English`, err);
  } finally {
    clearTimeout(timer);
  }
}

// Intl formatters are costly to make and the pages ask for the same few again and again: one per
// distinct set of options, kept.
function formatterCache(Make) {
  const made = new Map();
  return (options) => {
    const key = JSON.stringify(options);
    if (!made.has(key)) made.set(key, new Make(locale, options));
    return made.get(key);
  };
}
const numberFormat = formatterCache(Intl.NumberFormat);
const dateFormat = formatterCache(Intl.DateTimeFormat);

// `%(name)s` takes the value as text, `%(name)d` a whole number in the locale's digits and grouping
// (as Flask-Babel's format_number would), `%%` is a percent sign. A name not given stays as written,
// so a missing value shows, rather than a blank. As Flask-Babel's gettext, no values: no interpolation
// (a message with no placeholder writes a plain %).
export function interpolate(text, values) {
  if (!values || !Object.keys(values).length) return text;
  return text.replace(/%(?:\(([A-Za-z_][A-Za-z0-9_]*)\)([sd])|%)/g, (whole, name, kind) => {
    if (!name) return '%';
    if (!Object.prototype.hasOwnProperty.call(values, name)) return whole;
    const value = values[name];
    if (kind === 'd' && typeof value === 'number' && Number.isFinite(value)) {
      return numberFormat({ maximumFractionDigits: 0 }).format(Math.trunc(value));
    }
    return String(value);
  });
}

// The translation of an English message, interpolated; the English itself when the catalogue has none.
export function _(msgid, values) {
  const said = messages[msgid];
  return interpolate(typeof said === 'string' && said ? said : msgid, values);
}

export const gettext = _;

// A sentence the server made once for every viewer (rover_web/web/api_messages.py `said`): its English
// at source[key], its id and values at source[key + '_i18n'], translated here from events.po's entries
// in this page's catalogue. A value that is itself a sentence ({id, values}) is translated too. No
// wire form (an older server, a robot's own text): the English, as sent.
function fromWire(wire) {
  const values = {};
  for (const [name, value] of Object.entries(wire.values || {})) {
    values[name] = isWire(value) ? fromWire(value) : value;
  }
  return _(wire.id, values);
}
function isWire(value) {
  return Boolean(value) && typeof value === 'object' && typeof value.id === 'string';
}
export function said(source, key) {
  if (!source) return '';
  return saidWire(source[key] ?? '', source[`${key}_i18n`]);
}
// The same for a sentence and its wire form kept apart (a list of them: a robot's alerts on the hub).
export function saidWire(english, wire) {
  return isWire(wire) ? fromWire(wire) : english;
}

// gettext's plural forms from Intl's categories. Babel writes a language's forms in CLDR's order of
// categories (zero, one, two, few, many, other: Spanish's three are one, many for a round million, and
// other; English's two are one and other; Japanese has other alone), and Intl knows the same
// categories, so a category's place among the language's is its form's index. Should the browser's
// CLDR and Babel's ever disagree on the count, "one" is the first form and anything else the last.
const CATEGORY_ORDER = ['zero', 'one', 'two', 'few', 'many', 'other'];
const rules = new Intl.PluralRules(locale);
const categories = [...rules.resolvedOptions().pluralCategories]
  .sort((a, b) => CATEGORY_ORDER.indexOf(a) - CATEGORY_ORDER.indexOf(b));
function formIndex(n, count) {
  if (count <= 1) return 0;
  const category = rules.select(n);
  if (categories.length === count) return categories.indexOf(category);
  return category === 'one' ? 0 : count - 1;
}

// ngettext('%(num)d robot', '%(num)d robots', n, values): `num` is n unless values say otherwise,
// as in Flask-Babel's ngettext.
export function ngettext(singular, plural, n, values = {}) {
  const all = { num: n, ...values };
  const forms = plurals[singular];
  if (Array.isArray(forms) && forms.length && forms.every((form) => typeof form === 'string' && form)) {
    return interpolate(forms[formIndex(n, forms.length)], all);
  }
  const english = new Intl.PluralRules('en').select(n) === 'one' ? singular : plural;
  return interpolate(english, all);
}

// A number for people: `digits` fixes the decimals where the precision means something (0.25 m
// stays 0.25 m, never 0.3 m), the locale picks the separators. An object is Intl's own options.
export function formatNumber(value, digits = undefined) {
  const number = Number(value);
  if (!Number.isFinite(number)) return Number.isNaN(number) ? '–' : String(number);
  const options = typeof digits === 'number' ? { minimumFractionDigits: digits, maximumFractionDigits: digits }
    : (digits || {});
  return numberFormat(options).format(number);
}

// Unit symbols as the code writes them, to Intl's unit names where Intl writes the same symbol
// (its short "sec", "deg", "kb/s" would change what operators read); the others keep their symbol,
// after the locale's number: units are not translated.
const UNITS = {
  m: 'meter', km: 'kilometer', cm: 'centimeter', mm: 'millimeter', ms: 'millisecond',
  'm/s': 'meter-per-second', 'km/h': 'kilometer-per-hour', '%': 'percent',
  kB: 'kilobyte', MB: 'megabyte', GB: 'gigabyte',
};
const UNSPACED = new Set(['°']);

// formatUnit(0.25, 'm', 2) -> "0.25 m" (en), "0,25 m" (es). digits as in formatNumber.
export function formatUnit(value, unit, digits = undefined) {
  const number = Number(value);
  if (!Number.isFinite(number)) return `${formatNumber(number)} ${unit}`;
  const fixed = typeof digits === 'number' ? { minimumFractionDigits: digits, maximumFractionDigits: digits }
    : (digits || {});
  const name = UNITS[unit];
  if (name) {
    try {
      return numberFormat({ ...fixed, style: 'unit', unit: name, unitDisplay: 'short' }).format(number);
    } catch { /* an Intl without this unit: the symbol below */ }
  }
  return `${numberFormat(fixed).format(number)}${UNSPACED.has(unit) ? '' : ' '}${unit}`;
}

function asDate(value) {
  const date = value instanceof Date ? value : new Date(value);
  return Number.isNaN(date.getTime()) ? null : date;
}

// A clock time in the page's locale (seconds shown: a robot's events are seconds apart).
export function formatTime(value, options = { hour: '2-digit', minute: '2-digit', second: '2-digit' }) {
  const date = asDate(value);
  return date ? dateFormat(options).format(date) : '–';
}

// A date and time in the page's locale.
export function formatDateTime(value, options = { dateStyle: 'medium', timeStyle: 'medium' }) {
  const date = asDate(value);
  return date ? dateFormat(options).format(date) : '–';
}

// Names joined as the locale joins them ("a, b and c"; "a、b、c").
export function formatList(items, options = { style: 'long', type: 'conjunction' }) {
  const list = Array.from(items, String);
  try { return new Intl.ListFormat(locale, options).format(list); } catch { return list.join(', '); }
}
