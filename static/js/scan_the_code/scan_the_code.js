// Scan the Code panel: boxes, live light tower, detected code, freshness, history.
// Every string from the robot is set with textContent; colour names become CSS values only when
// they are one of the configured colours (or black).
import { on, onServerState } from '../live/live.js';
import { _, formatNumber, formatTime } from '../core/i18n.js';

const card = document.getElementById('scan-the-code');
// The usual colour names in the page's language; a colour configured under another name shows as
// it is configured (ROVER_WEB settings). The data-colour attributes keep the configured names.
const COLOUR_WORDS = {
  red: _('red'), green: _('green'), blue: _('blue'), yellow: _('yellow'), white: _('white'), black: _('black'),
  orange: _('orange'), purple: _('purple'),
};
// Why a cycle made no code, and what it made (rover_web/scan_the_code/light_sequence.py).
const PROBLEMS = {
  unknown_colour: _('unknown colour'), too_many_colours: _('too many colours'), too_few_colours: _('too few colours'),
  stream_gap: _('stream gap'),
};
const RESULTS = { invalid: _('invalid'), incomplete: _('incomplete') };
const TOWER_KEY = 'rover_web.scan_the_code.tower_hidden';

if (card) {
  const $ = (id) => document.getElementById(id);
  let colours = new Set((card.dataset.colours || '').split(',').filter(Boolean));
  let lastState = null;

  const paint = (el, colour) => {
    el.dataset.colour = colour || 'none';
    if (colour === 'black' || colours.has(colour)) el.style.setProperty('--c', colour);
    else el.style.removeProperty('--c');
  };
  // The server-rendered colours too: the Content-Security-Policy allows no inline style attributes.
  for (const el of card.querySelectorAll('[data-colour]')) paint(el, el.dataset.colour);
  const problemsText = (list) => list.map((p) => PROBLEMS[p] || p.replaceAll('_', ' ')).join(', ');
  const clock = (epochS) => formatTime(epochS * 1000, { hour: '2-digit', minute: '2-digit', second: '2-digit', hourCycle: 'h23' });
  const colourWord = (c) => COLOUR_WORDS[c] || c;
  const span = (cls, text) => {
    const el = document.createElement('span');
    el.className = cls;
    el.textContent = text;
    return el;
  };

  const setFresh = (state) => {
    const pill = $('stc-fresh');
    const labels = { ok: _('live'), stale: _('stale'), no_data: _('no data'), unknown: _('unknown') };
    pill.dataset.state = state;
    pill.querySelector('b').textContent = labels[state];
    card.classList.toggle('stc-stale', state !== 'ok');
  };
  const freshness = (s) => (s.fresh ? 'ok' : s.last_message_at ? 'stale' : 'no_data');

  const renderCode = (s) => {
    const code = $('stc-code');
    code.dataset.confirmed = s.code && s.code.confirmed ? 'yes' : 'no';
    if (!s.code) {
      code.replaceChildren(span('stc-none', _('no code yet')));
      $('stc-code-meta').textContent = _('waiting for three colours and black');
      return;
    }
    code.replaceChildren(...s.code.colours.map((c) => {
      const chip = span('stc-chip', colourWord(c));
      paint(chip, c);
      return chip;
    }));
    const confidence = _('confidence %(n)s', { n: s.code.confidence });
    const pending = s.code.confirmed ? '' : ` ${_('(confirmed at %(n)s)', { n: s.confirm_cycles })}`;
    $('stc-code-meta').textContent = `${confidence}${pending} · ${_('seen %(time)s', { time: clock(s.code.seen_at) })}`;
  };

  const renderBoxes = (s) => {
    const boxes = $('stc-boxes').querySelectorAll('.stc-box');
    s.boxes.forEach((c, i) => {
      if (!boxes[i]) return;
      paint(boxes[i], c);
      boxes[i].querySelector('.stc-box-name').textContent = c === null ? '' : colourWord(c);
    });
    const note = $('stc-cycle');
    note.dataset.problem = s.cycle.problems.length ? 'yes' : 'no';
    note.textContent = s.cycle.problems.length ? _('this cycle is invalid: %(problems)s', { problems: problemsText(s.cycle.problems) }) : '';
  };

  const renderLight = (s) => {
    paint($('stc-lamp'), s.light);
    $('stc-light').textContent = s.light === null ? _('no message yet')
      : s.light === 'unknown' ? _('unknown: %(text)s', { text: s.light_text }) : colourWord(s.light);
  };

  const renderHistory = (s) => {
    $('stc-history').replaceChildren(...s.history.map((h) => {
      const li = document.createElement('li');
      li.dataset.result = h.result;
      const extra = h.length > h.colours.length ? ` (+${h.length - h.colours.length})` : '';
      li.append(span('stc-when', clock(h.at)), ' ', span('stc-what', h.colours.map(colourWord).join(', ') + extra), ' ',
        span('stc-result', h.result === 'code' ? _('code') : `${RESULTS[h.result] || h.result}: ${problemsText(h.problems)}`));
      return li;
    }));
  };

  on('light_sequence', (s) => {
    lastState = s;
    colours = new Set(s.colours);
    card.dataset.colours = s.colours.join(',');
    card.dataset.revision = String(s.revision);
    renderCode(s);
    renderBoxes(s);
    renderLight(s);
    $('stc-unknown').textContent = formatNumber(s.counts.unknown_messages);
    $('stc-invalid').textContent = formatNumber(s.counts.invalid_cycles);
    $('stc-incomplete').textContent = formatNumber(s.counts.incomplete_cycles);
    renderHistory(s);
    setFresh(freshness(s));
  });

  // Without the event stream the server's freshness is unknown here, whatever it was last.
  onServerState((state) => {
    if (state === 'reconnecting' || state === 'lost') setFresh('unknown');
    else if (state === 'live' && lastState) setFresh(freshness(lastState));
  });

  // The RobotX GUI's Show/Hide for the light tower; remembered per browser.
  const toggle = $('stc-tower-toggle');
  const tower = $('stc-tower');
  const showTower = (visible) => {
    tower.hidden = !visible;
    toggle.textContent = visible ? _('Hide') : _('Show');
    toggle.setAttribute('aria-expanded', String(visible));
  };
  let stored = null;
  try { stored = localStorage.getItem(TOWER_KEY); } catch { /* storage may be disabled */ }
  showTower(stored !== '1');
  toggle.addEventListener('click', () => {
    const visible = tower.hidden;
    showTower(visible);
    try { localStorage.setItem(TOWER_KEY, visible ? '0' : '1'); } catch { /* ignore */ }
  });
}
