// The Drive card's open WebSocket, as other modules may use it: the e-stop sends {"estop": true}
// over it first, since an open socket needs no free HTTP connection and no new request.
let sender = null;

export function setEstopSender(fn) { sender = fn; }

// True if the frame went out on an open socket.
export function sendEstopOverSocket() {
  try { return Boolean(sender && sender()); } catch { return false; }
}
