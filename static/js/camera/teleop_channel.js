// The `teleop` data channel of the camera card's WebRTC session, as the Drive card may use it:
// unordered and without retransmits, so a lost packet delays nothing behind it. The Drive card
// keeps its WebSocket; while this channel is open it may send its frames here instead (same
// frames, same replies: the server runs the same rules for both) and show "data channel".
//
//   import { teleopChannel } from './camera/teleop_channel.js';
//   teleopChannel.isOpen()            true while frames can go out on it
//   teleopChannel.send(obj)           false when not open (send over the WebSocket then)
//   teleopChannel.onMessage(fn)       fn(message) for every frame the server sends (hello, state, error)
//   teleopChannel.onChange(fn)        fn(isOpen) when the channel opens or closes
//   teleopChannel.socket()            a WebSocket look-alike on the channel (readyState, send, close,
//                                     onmessage, onclose) whose first message is the channel
//                                     session's hello, brought up to date: code written for the
//                                     socket takes it unchanged

const OPEN = 1;
const CLOSED = 3;
const messageListeners = new Set();
let hello = null;  // the channel session's hello, with the latest state frame's fields applied
const changeListeners = new Set();
let channel = null;

function changed() {
  const open = teleopChannel.isOpen();
  for (const fn of changeListeners) { try { fn(open); } catch { /* one listener must not stop the others */ } }
}

export const teleopChannel = {
  isOpen() { return channel !== null && channel.readyState === 'open'; },
  send(obj) {
    if (!this.isOpen()) return false;
    try { channel.send(JSON.stringify(obj)); return true; } catch { return false; }
  },
  onMessage(fn) { messageListeners.add(fn); return () => messageListeners.delete(fn); },
  onChange(fn) { changeListeners.add(fn); return () => changeListeners.delete(fn); },
  socket() { return this.isOpen() ? socketOn(channel) : null; },
};

// Called by camera/webrtc.js with the channel it created (null when its session ends).
export function attachTeleopChannel(dc) {
  if (channel === dc) return;
  channel = dc;
  if (dc) {
    dc.addEventListener('open', changed);
    dc.addEventListener('close', () => { if (channel === dc) channel = null; changed(); });
    dc.addEventListener('message', (ev) => {
      let m;
      try { m = JSON.parse(ev.data); } catch { return; }
      // The server's measuring ping (a channel has none of its own, as a WebSocket has): answered
      // here at once, whoever uses the channel, so the round trip is the link's and not the page's.
      if (m.type === 'ping') {
        try { dc.send(JSON.stringify({ pong: m.id })); } catch { /* closing */ }
        return;
      }
      if (m.type === 'hello') hello = m;
      else if (m.type === 'state' && hello) hello = { ...hello, ...m, type: 'hello' };
      for (const fn of messageListeners) { try { fn(m); } catch { /* see above */ } }
    });
  } else {
    hello = null;
  }
  changed();
}

function socketOn(dc) {
  const sock = {
    readyState: OPEN, onmessage: null, onclose: null,
    send(text) { if (sock.readyState === OPEN) dc.send(text); },
    close() { end(); },
  };
  const forward = (m) => { if (sock.readyState === OPEN && sock.onmessage) sock.onmessage({ data: JSON.stringify(m) }); };
  // Until the hello has gone, a state frame is only folded into it (see attachTeleopChannel) and
  // anything else waits: a state let through first had reached the caller before its hello.
  let greeted = false;
  const early = [];
  const offMessage = teleopChannel.onMessage((m) => {
    if (greeted) forward(m);
    else if (m.type !== 'state' && m.type !== 'hello') early.push(m);
  });
  const offChange = teleopChannel.onChange((open) => { if (!open) end(); });
  function end() {
    if (sock.readyState === CLOSED) return;
    sock.readyState = CLOSED;
    offMessage();
    offChange();
    setTimeout(() => { if (sock.onclose) sock.onclose({ code: 1000 }); }, 0);
  }
  // As a WebSocket would: the hello comes first, after the caller has set its handlers.
  setTimeout(() => {
    greeted = true;
    if (hello) forward(hello);
    early.splice(0).forEach(forward);
  }, 0);
  return sock;
}
