// The Drive card's gamepad: reads the browser's Gamepad API and hands teleop.js a command while
// the enable button is held. The mapping and the enable logic are in gamepad.js (pure, tested on
// its own); this file only polls, paces and shows.
//
// The pad is read once per animation frame, and only while the page is visible and a pad is
// connected. A new value is handed on at most once per teleop period; teleop.js sends it and
// repeats it, as for the joystick. A pad that goes away, enable let go, or a page stop (hidden tab,
// blur, Space) ends the command at once; after a page stop or a lost pad, enable must be let go
// and pressed again. If the reading stalls while a command is held (no animation frame for
// STALE_MS), the command ends as well: a frozen reading must not be repeated as a held input.
import { DEFAULTS, EnableGate, normalizeConfig, pace, readPad } from './gamepad.js';
import { _, formatNumber } from '../core/i18n.js';

const KEY = 'rover_web.gamepad';
const STALE_MS = 200;

export function loadConfig() {
  try {
    return normalizeConfig(JSON.parse(localStorage.getItem(KEY) || '{}'));
  } catch {
    return normalizeConfig({});
  }
}

function saveConfig(config) {
  try { localStorage.setItem(KEY, JSON.stringify(config)); } catch { /* private mode: this page only */ }
}

// `onChange()` is called whenever the command changes; `command()` is what the pad asks for now;
// `sentAt()` is when teleop.js last sent a drive frame (of any source, keep-alives included), so a
// changing stick adds no frame within the teleop period of another.
export function startGamepad({ onChange, sentAt }) {
  const $ = (id) => document.getElementById(id);
  const shown = new Map();
  const text = (id, value) => {
    if (shown.get(id) === value) return;
    shown.set(id, value);
    const el = $(id);
    if (el) el.textContent = value;
  };
  const box = $('gamepad');
  const mark = (state) => { if (box) box.dataset.state = state; };

  const available = window.isSecureContext && typeof navigator.getGamepads === 'function';
  let config = loadConfig();
  const gate = new EnableGate();
  let index = null;         // the pad in use (Gamepad.index)
  let handed = null;        // the command last handed to teleop.js
  let readAt = -Infinity;   // when the pad was last read
  let periodMs = 25;        // 1 / the server's rate_hz, from its hello
  let frame = null;

  function pads() {
    try { return Array.from(navigator.getGamepads() || []).filter((p) => p && p.connected !== false); } catch { return []; }
  }

  function hand(want) {
    handed = want;
    onChange();
  }

  function showIdle(state, name) {
    mark(state);
    text('gamepad-name', name);
    text('gamepad-enable', '—');
    text('gamepad-stick', '—');
  }

  // The pad in use went away: stop now, and take another connected pad if there is one.
  function lost() {
    index = null;
    gate.block();
    if (handed) hand(null);
    const next = pads()[0];
    if (next) index = next.index;
    else showIdle('none', _('none connected: press a button on it'));
    schedule();
  }

  function poll() {
    frame = null;
    const now = performance.now();
    const pad = pads().find((p) => p.index === index);
    if (!pad) {
      lost();
      return;
    }
    readAt = now;
    const reading = readPad(pad, config);
    const want = gate.command(reading);
    if (pace(handed, want, now, sentAt(), periodMs)) hand(want);
    mark(want ? 'driving' : gate.blocked ? 'blocked' : reading.enable ? 'enabled' : 'connected');
    text('gamepad-name', pad.mapping === 'standard' ? pad.id : _('%(pad)s (not standard mapping: check the axes)', { pad: pad.id }));
    text('gamepad-enable', reading.enable ? (gate.blocked ? _('held: let go and press again') : _('held')) : _('released'));
    text('gamepad-stick', _('linear %(linear)s, angular %(angular)s',
      { linear: formatNumber(reading.linear, 2), angular: formatNumber(reading.angular, 2) }));
    schedule();
  }

  function schedule() {
    if (frame === null && index !== null && document.visibilityState === 'visible') {
      frame = requestAnimationFrame(poll);
    }
  }

  function command() {
    if (!handed) return null;
    if (performance.now() - readAt > STALE_MS) {  // the reading stalled: nothing is held any more
      gate.block();
      handed = null;
      return null;
    }
    return handed;
  }

  // teleop.js's own stops (hidden tab, pagehide, blur, Space): end the command, enable again to drive.
  function suppress() {
    gate.block();
    handed = null;
  }

  // --- configuration, per browser ---
  const fields = {
    linearAxis: $('gamepad-linear-axis'), angularAxis: $('gamepad-angular-axis'),
    invertLinear: $('gamepad-invert-linear'), invertAngular: $('gamepad-invert-angular'),
    deadZone: $('gamepad-dead-zone'), enableButton: $('gamepad-enable-button'),
  };
  function fill() {
    for (const [key, el] of Object.entries(fields)) {
      if (!el) continue;
      if (el.type === 'checkbox') el.checked = config[key];
      else el.value = String(config[key]);
    }
  }
  function readForm() {
    const raw = {};
    for (const [key, el] of Object.entries(fields)) {
      if (el) raw[key] = el.type === 'checkbox' ? el.checked : el.value;
    }
    config = normalizeConfig(raw);
    saveConfig(config);
    fill();
  }
  for (const el of Object.values(fields)) if (el) el.addEventListener('change', readForm);
  const reset = $('gamepad-reset');
  if (reset) {
    reset.addEventListener('click', () => {
      config = normalizeConfig(DEFAULTS);
      saveConfig(config);
      fill();
    });
  }
  fill();

  if (!available) {
    showIdle('unavailable', _('unavailable: browsers expose gamepads only on secure pages (localhost or HTTPS)'));
    return { command: () => null, suppress() {}, setRate() {} };
  }

  window.addEventListener('gamepadconnected', (e) => {
    if (index === null && e.gamepad) index = e.gamepad.index;
    schedule();
  });
  window.addEventListener('gamepaddisconnected', (e) => {
    if (e.gamepad && e.gamepad.index === index) lost();
  });
  document.addEventListener('visibilitychange', () => {
    if (document.visibilityState === 'visible') schedule();
    else if (frame !== null) {
      cancelAnimationFrame(frame);
      frame = null;
    }
  });
  const first = pads()[0];
  if (first) index = first.index;
  else showIdle('none', _('none connected: press a button on it'));
  schedule();

  return {
    command,
    suppress,
    setRate(hz) { if (Number.isFinite(hz) && hz > 0) periodMs = 1000 / hz; },
  };
}
