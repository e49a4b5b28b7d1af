// The gamepad's pure logic, with no DOM and no timers, so it is tested on its own in Chromium
// (tests/browser/test_gamepad.py): a pad's axes through a dead zone to teleop fractions, the enable
// button, and when a new value may go out. The Drive card's glue is teleop_gamepad.js.
//
// Standard mapping (https://w3c.github.io/gamepad/#remapping): axes 0 and 1 are the left stick's
// x and y, where -1 is left and up; button 4 is the left shoulder. Forward is +linear and a turn
// to the left is +angular (REP 103), so both axes are negated before the operator's inversions.

export const DEFAULTS = Object.freeze({
  linearAxis: 1, angularAxis: 0, invertLinear: false, invertAngular: false, deadZone: 0.15, enableButton: 4,
});
export const MAX_AXIS = 15;
export const MAX_BUTTON = 31;
export const MAX_DEAD_ZONE = 0.9;

const whole = (v, max, fallback) => {
  const n = typeof v === 'string' && v.trim() !== '' ? Number(v) : v;
  return Number.isInteger(n) && n >= 0 && n <= max ? n : fallback;
};

// Whatever was stored or typed, a complete and valid configuration: anything out of range falls
// back to its default rather than to something that might drive.
export function normalizeConfig(raw) {
  const src = raw && typeof raw === 'object' ? raw : {};
  const dz = typeof src.deadZone === 'string' && src.deadZone.trim() !== '' ? Number(src.deadZone) : src.deadZone;
  return {
    linearAxis: whole(src.linearAxis, MAX_AXIS, DEFAULTS.linearAxis),
    angularAxis: whole(src.angularAxis, MAX_AXIS, DEFAULTS.angularAxis),
    invertLinear: src.invertLinear === true,
    invertAngular: src.invertAngular === true,
    deadZone: Number.isFinite(dz) && dz >= 0 && dz <= MAX_DEAD_ZONE ? dz : DEFAULTS.deadZone,
    enableButton: whole(src.enableButton, MAX_BUTTON, DEFAULTS.enableButton),
  };
}

// Below the dead zone 0; beyond it rescaled, so the output still runs smoothly from 0 to ±1.
// Per axis, so a stick pushed straight ahead does not drift into a turn.
export function applyDeadZone(value, deadZone) {
  if (typeof value !== 'number' || !Number.isFinite(value)) return 0;
  const v = Math.max(-1, Math.min(1, value));
  const magnitude = Math.abs(v);
  if (magnitude <= deadZone) return 0;
  return Math.sign(v) * Math.min(1, (magnitude - deadZone) / (1 - deadZone));
}

const axis = (pad, i) => (pad && pad.axes && i < pad.axes.length ? pad.axes[i] : 0);
const tidy = (v) => Math.round(v * 1000) / 1000 + 0;  // three decimals, as the page sends; never -0

export function buttonHeld(pad, index) {
  const b = pad && pad.buttons ? pad.buttons[index] : undefined;
  if (b === undefined || b === null) return false;
  if (typeof b === 'number') return b > 0.5;  // very old implementations gave bare values
  return b.pressed === true || (typeof b.value === 'number' && b.value > 0.5);
}

// One reading of a pad: the raw stick, the fractions it asks for, and whether enable is held.
export function readPad(pad, config) {
  const rawLinear = axis(pad, config.linearAxis);
  const rawAngular = axis(pad, config.angularAxis);
  const linear = -applyDeadZone(rawLinear, config.deadZone) * (config.invertLinear ? -1 : 1);
  const angular = -applyDeadZone(rawAngular, config.deadZone) * (config.invertAngular ? -1 : 1);
  return {
    enable: buttonHeld(pad, config.enableButton),
    linear: tidy(linear),
    angular: tidy(angular),
    raw: [Number.isFinite(rawLinear) ? rawLinear : 0, Number.isFinite(rawAngular) ? rawAngular : 0],
  };
}

// The enable button as a deadman of the page's own: a command only while it is held. After a stop
// the page made by itself (hidden tab, blur, Space, a pad that went away), enable must be let go
// and pressed again, as the joystick must be pressed again.
export class EnableGate {
  constructor() { this.blocked = false; }

  block() { this.blocked = true; }

  // `reading` null: no pad. Returns {linear, angular} to drive with, or null for "not driving".
  command(reading) {
    if (!reading || !reading.enable) {
      this.blocked = false;
      return null;
    }
    if (this.blocked) return null;
    return { linear: reading.linear, angular: reading.angular };
  }
}

// What to do with the latest command, given the last one handed on and when: 'stop' and the first
// 'drive' at once, a changed value at most once per teleop period (the pad is read every animation
// frame, at 60 to 240 Hz; the server's rate is 40 Hz), null for nothing new.
export function pace(sent, want, nowMs, sentAtMs, periodMs) {
  if (!want) return sent ? 'stop' : null;
  if (!sent) return 'drive';
  if (want.linear === sent.linear && want.angular === sent.angular) return null;
  return nowMs - sentAtMs >= periodMs ? 'drive' : null;
}
