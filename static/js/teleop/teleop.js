// The Drive panel: virtual joystick (nipplejs), keyboard and gamepad over the /ws/teleop WebSocket.
//
// The server decides when the robot stops: it repeats the held command at its own rate and stops
// it when this page falls silent for its deadman time. The page only says what the operator holds,
// repeating it every keepalive_s while held, and says stop on release, Space, a hidden tab,
// pagehide and blur. After a stop it did not ask for (deadman, e-stop, takeover), the server sends
// a new epoch; frames carrying the old one are dropped, so only input sent after that notice moves
// the robot again.
import { base } from '../core/api.js';
import { on } from '../live/live.js';
import { operatorName, setOperatorName } from '../core/operator.js';
import { startGamepad } from './teleop_gamepad.js';
import { setEstopSender } from './teleop_link.js';
import { teleopChannel } from '../camera/teleop_channel.js';
import { linkView } from './link_view.js';
import { _, formatNumber, formatUnit } from '../core/i18n.js';

const REARM = _('E-stop released: let go of the stick, keys or gamepad to re-arm.');
// The server's words for what drives and why it last stopped (rover_web/teleop/control.py).
const SOURCES = { joystick: _('joystick'), keyboard: _('keyboard'), gamepad: _('gamepad') };
const STOP_REASONS = {
  operator: _('operator'), disconnected: _('disconnected'), taken_over: _('taken over'), released: _('released'),
  rest_stop: _('stop request'), estop: _('e-stop'), link_lost: _('link lost'), duration_elapsed: _('duration elapsed'),
  deadman: _('deadman'), bad_input: _('bad input'),
};
import { onThemeChange, themeColour } from '../core/theme.js';

const card = document.getElementById('teleop-card');
if (card) start();

function start() {
  const $ = (id) => document.getElementById(id);
  const KEYS = {
    KeyW: 'up', ArrowUp: 'up', KeyS: 'down', ArrowDown: 'down',
    KeyA: 'left', ArrowLeft: 'left', KeyD: 'right', ArrowRight: 'right',
  };

  let ws = null;
  let session = null;
  let epoch = 0;
  let inControl = false;
  let holder = null;
  const closedSessions = new Set();  // ids of this page's sockets that it closed or lost
  let estop = card.dataset.mode === 'estop';
  let keepaliveMs = 100;
  let retryMs = 500;
  let stick = null;            // {linear, angular} while the joystick is held
  let stickSuppressed = false; // after a stop by blur/hide/Space the stick must be pressed again
  const keys = new Set();
  let keySpeed = 0.5;
  let repeatTimer = null;
  let driving = false;         // a drive frame went out since the last stop
  let sentAt = -Infinity;      // when the last drive frame went out (performance.now())
  let periodMs = 25;           // the server's repeat period, 1 / rate_hz
  let seq = 0;                 // numbers this socket's drive and stop frames, so the server drops any that come late
  let transport = 'websocket'; // or 'datachannel': unordered, and a lost frame is not sent again
  let stopRepeats = [];        // timers sending the last stop again over the data channel
  const linkFigures = linkView();
  const STOP_REPEAT_MS = [50, 100, 150];

  const clamp = (v) => (Number.isFinite(v) ? Math.max(-1, Math.min(1, v)) : 0);
  const round = (v) => Math.round(clamp(v) * 1000) / 1000;
  const text = (id, value) => { const el = $(id); if (el) el.textContent = value; };

  function message(msg) { text('teleop-message', msg); }

  // The server decides who may drive; a viewer's page does not even open the socket.
  if (document.body.dataset.canOperate === 'no') {
    card.dataset.mode = 'read-only';
    text('teleop-link', _('view only'));
    message(card.dataset.readonlyReason || _('Driving needs the operator role.'));
    text('gamepad-name', _('view only'));
    on('teleop', (s) => {
      text('teleop-linear', formatNumber(s.linear_mps, 2));
      text('teleop-angular', formatNumber(s.angular_rps, 2));
      text('teleop-holder', s.holder ? s.holder.name : _('free'));
    });
    return;
  }

  // Started before the socket: its command counts once the socket is open and this page may drive.
  const gamepad = startGamepad({ onChange: () => update(), sentAt: () => sentAt });

  function send(obj) {
    if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(obj));
  }

  function wanted() {
    if (stick) return { linear: stick.linear, angular: stick.angular, source: 'joystick' };
    const pad = gamepad.command();
    if (pad) return { linear: pad.linear, angular: pad.angular, source: 'gamepad' };
    if (keys.size) {
      const axis = (a, b) => (keys.has(a) ? 1 : 0) - (keys.has(b) ? 1 : 0);
      return { linear: keySpeed * axis('up', 'down'), angular: keySpeed * axis('left', 'right'), source: 'keyboard' };
    }
    return null;
  }

  const mayDrive = () => !estop && (inControl || holder === null);
  // A holder that is one of this page's own closed sockets holds nothing: the server freed control
  // when that socket closed. Messages made before the close still name it: the data channel's
  // hello when the card moves onto the channel (made while the socket still held control), or an
  // event-stream update that was on its way. Taken at their word, they left a press held across
  // the move waiting, view-only, for a stream update saying control is free, which a slow stream
  // brings late and a fast one may bring before the hello, i.e. never after it.
  const live = (h) => (h && closedSessions.has(h.id) ? null : h);
  function closed(id) {
    if (!id) return;
    closedSessions.add(id);
    if (closedSessions.size > 16) closedSessions.delete(closedSessions.values().next().value);  // reconnects add up
    holder = live(holder);
  }

  function sendDrive() {
    const cmd = wanted();
    if (!cmd || !mayDrive()) return;
    // t: when it left, on this page's monotonic clock; the server measures jitter and stalls from it
    // and dates the frame's freshness from it (docs/teleop.md).
    cancelStopRepeats();
    seq += 1;
    send({
      linear: round(cmd.linear), angular: round(cmd.angular), epoch, source: cmd.source,
      seq, t: Math.round(performance.now() * 10) / 10,
    });
    driving = true;
    sentAt = performance.now();
  }

  // A stop carries a seq too: a drive frame sent before it but delivered after it (the data channel
  // keeps no order) is then dropped by the server. Over the channel a lost stop is not sent again,
  // which would leave the robot to the deadman: it goes out STOP_REPEAT_MS more times with the same
  // seq. The server acts on the first to arrive and ignores the rest, and any that a newer press
  // overtook.
  function sendStop() {
    cancelStopRepeats();
    seq += 1;
    const frame = { stop: true, seq };
    send(frame);
    if (transport !== 'datachannel') return;
    const sock = ws;
    stopRepeats = STOP_REPEAT_MS.map((ms) => setTimeout(() => { if (ws === sock) send(frame); }, ms));
  }

  function cancelStopRepeats() {
    stopRepeats.forEach(clearTimeout);
    stopRepeats = [];
  }

  function stopRepeat() {
    clearInterval(repeatTimer);
    repeatTimer = null;
  }

  // The keep-alive: repeats what is held, unless a frame went out within the server's period
  // anyway (a gamepad sends its changes at that rate), or says stop if what was held ended without
  // telling update() (a gamepad reading that stalled).
  function repeat() {
    if (!wanted()) update();
    else if (performance.now() - sentAt >= periodMs) sendDrive();
  }

  // Called whenever what the operator holds changes.
  function update() {
    if (!wanted()) {
      stopRepeat();
      if (driving) sendStop();
      driving = false;
      return;
    }
    sendDrive();
    if (!repeatTimer) repeatTimer = setInterval(repeat, keepaliveMs);
  }

  // Blur, hidden tab, pagehide, Space: forget everything held and tell the server at once.
  function stopAll() {
    if (stick) stickSuppressed = true;
    stick = null;
    keys.clear();
    gamepad.suppress();
    stopRepeat();
    if (driving) sendStop();
    driving = false;
  }

  function render() {
    const mode = estop ? 'estop' : inControl ? 'driving' : holder ? 'view-only' : 'free';
    card.dataset.mode = mode;
    text('teleop-holder', inControl ? _('you (%(name)s)', { name: holder ? holder.name : operatorName() })
      : holder ? _('%(name)s (view only)', { name: holder.name }) : _('free'));
    $('teleop-takeover').hidden = !(holder && !inControl) || !session;
    $('teleop-release').hidden = !inControl;
    if (estop) message(_('E-stop engaged: release it to drive.'));
    else if (mode === 'view-only') message(_('%(name)s is driving. Take control to drive.', { name: holder.name }));
  }

  function onServerMessage(m) {
    if (m.type === 'hello') {
      session = m.session;
      keepaliveMs = Math.max(20, 1000 * m.keepalive_s);
      periodMs = 1000 / m.rate_hz;
      gamepad.setRate(m.rate_hz);
      retryMs = 500;
      const link = $('teleop-link');
      link.dataset.state = 'live';
      transport = m.transport || 'websocket';
      link.dataset.transport = transport;  // the camera's data channel, when it is up
      link.textContent = m.transport === 'datachannel' ? _('connected as %(name)s (data channel)', { name: m.name })
        : _('connected as %(name)s', { name: m.name });
    }
    if (m.link) linkFigures.show(m.link);
    // The periodic report: nothing changed, unless it names a newer epoch. Over the data channel a
    // state frame can be lost (no retransmits): a stop notice that never came would leave every
    // frame of a held press refused as stale. Epochs only grow, so an older report changes nothing.
    if (m.type === 'state' && m.reason === 'link' && !(m.epoch > epoch)) return;
    if (m.type === 'hello' || m.type === 'state') {
      epoch = m.epoch;
      inControl = m.in_control;
      holder = live(m.holder);
      estop = m.estop;
      if (m.reason === 'deadman') message(_('Stopped: no input reached the server in time.'));
      else if (m.reason === 'taken_over' && !inControl) message(_('Another operator took control.'));
      else if (m.reason === 'in_control') message('');
      else if (m.reason === 'estop_released') {
        message(m.armed === false && wanted() ? REARM : '');
      }
      render();
      if (wanted()) sendDrive();  // still held: the new epoch makes this a fresh, live input
    } else if (m.type === 'error' && m.error === 'rearm_required') {
      message(REARM);
    } else if (m.type === 'error' && !['stale_epoch', 'stale_seq', 'late_frame'].includes(m.error)) {
      message(m.message);
    }
  }

  setEstopSender(() => {
    if (!ws || ws.readyState !== WebSocket.OPEN) return false;
    ws.send(JSON.stringify({ estop: true }));
    return true;
  });

  function connect() {
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    ws = teleopChannel.socket()
      || new WebSocket(`${scheme}//${location.host}${base}/ws/teleop?name=${encodeURIComponent(operatorName())}`);
    seq = 0;  // a new socket (or data channel) is a new session on the server
    cancelStopRepeats();  // their seq belongs to the old session
    transport = 'websocket';  // until the hello says otherwise
    ws.onmessage = (ev) => {
      let m;
      try { m = JSON.parse(ev.data); } catch { return; }
      onServerMessage(m);
    };
    ws.onclose = () => {
      closed(session);
      session = null;
      inControl = false;
      driving = false;
      const link = $('teleop-link');
      link.dataset.state = 'reconnecting';
      link.textContent = _('reconnecting');
      linkFigures.clear();
      render();
      setTimeout(connect, retryMs);
      retryMs = Math.min(retryMs * 2, 5000);
    };
  }

  // The camera's data channel opened: move over to it at once (it ends itself when the channel closes).
  teleopChannel.onChange((open) => {
    if (!open || !ws) return;
    const old = ws;
    old.onclose = null;
    old.close();  // the server frees control this socket held (and zeroes the robot if it moved)
    closed(session);
    session = null;
    inControl = false;
    driving = false;
    connect();
  });

  // --- inputs ---

  const joystick = window.nipplejs.create({
    zone: $('teleop-joystick'), mode: 'static', position: { left: '50%', top: '50%' },
    color: themeColour('--stick', '#58a6ff'), size: 150, restOpacity: 0.7,
  });
  // nipplejs paints its knob once: a new theme repaints it.
  onThemeChange(() => {
    for (const el of $('teleop-joystick').querySelectorAll('.nipple .back, .nipple .front')) {
      el.style.background = themeColour('--stick', '#58a6ff');
    }
  });
  joystick.on('start', () => {
    stickSuppressed = false;
    stick = { linear: 0, angular: 0 };
    update();
  });
  joystick.on('move', (_evt, data) => {
    if (stickSuppressed) return;
    // vector is the knob offset over the radius: +y is up (forward), +x is right (turn right, -z).
    stick = { linear: clamp(data.vector.y), angular: clamp(-data.vector.x) };
    update();
  });
  joystick.on('end', () => {
    stickSuppressed = false;
    stick = null;
    update();
  });

  const typing = (el) => el && el.closest && el.closest('input, textarea, select, [contenteditable="true"]');
  window.addEventListener('keydown', (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.code === 'Space') {
      if (typing(e.target) && e.target.type !== 'range') return;
      // Space on a focused button still presses it (E-STOP by keyboard: docs/accessibility.md);
      // anywhere else it only stops, and does not scroll the page.
      const control = e.target.closest && e.target.closest('button, summary, a[href], [role="button"]');
      if (!control) e.preventDefault();
      stopAll();
      return;
    }
    const dir = KEYS[e.code];
    if (!dir || typing(e.target)) return;
    e.preventDefault();
    if (!keys.has(dir)) {
      keys.add(dir);
      update();
    }
  });
  window.addEventListener('keyup', (e) => {
    const dir = KEYS[e.code];
    if (dir && keys.delete(dir)) update();
  });
  document.addEventListener('visibilitychange', () => {
    if (document.visibilityState === 'hidden') stopAll();
  });
  window.addEventListener('pagehide', stopAll);
  window.addEventListener('blur', stopAll);

  $('teleop-takeover').addEventListener('click', () => send({ takeover: true }));
  $('teleop-release').addEventListener('click', () => { stopAll(); send({ release: true }); });
  const speed = $('teleop-key-speed');
  speed.addEventListener('input', () => {
    keySpeed = Number(speed.value) / 100;
    text('teleop-key-speed-out', formatUnit(Number(speed.value), '%'));
  });
  const name = $('teleop-name');
  name.value = operatorName();
  name.addEventListener('change', () => {
    name.value = setOperatorName(name.value);
    if (ws) ws.close();  // reconnect under the new name
  });

  // --- what everyone sees ---

  on('teleop', (s) => {
    text('teleop-linear', formatNumber(s.linear_mps, 2));
    text('teleop-angular', formatNumber(s.angular_rps, 2));
    text('teleop-source', s.source ? SOURCES[s.source] || s.source : '');
    text('teleop-last-stop', s.last_stop ? STOP_REASONS[s.last_stop.reason] || s.last_stop.reason.replaceAll('_', ' ') : '—');
    // Who holds control, for display and for claiming a free robot. Whether *this* socket holds it
    // comes from the socket itself: an SSE update can be a little older than the socket's news.
    if (!inControl) holder = live(s.holder);
    estop = s.estop.engaged;
    render();
  });

  connect();
}
