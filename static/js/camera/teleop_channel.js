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

const messageListeners = new Set();
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
      for (const fn of messageListeners) { try { fn(m); } catch { /* see above */ } }
    });
  }
  changed();
}
