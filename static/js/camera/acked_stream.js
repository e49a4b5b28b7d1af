// MJPEG read by the page itself, which tells the server how much it has received. An <img> cannot
// say that, and the server's own view of the path (its socket's queue) is blind behind a hop that
// terminates TCP (nginx, a satellite link's proxy): such a hop acknowledges everything at once and
// the video piles up in its buffer, in front of the e-stop. So the page fetches
// GET /stream?...&ack=1, cuts the multipart body into JPEGs by their Content-Length, shows each in
// the card's <img> (a blob: URL), and after each one POSTs the body bytes received so far to
// /api/camera/viewers/<X-Camera-Viewer>/ack; the server writes no more than about a frame beyond
// what the page has acknowledged (docs/camera.md#acknowledging-pages).

import { api, at, errorFrom } from '../core/api.js';
import { _ } from '../core/i18n.js';

const HEAD_END = [13, 10, 13, 10];  // \r\n\r\n
const RETRY_ACK_MS = 500;  // an ack refused or not answered: send the newest count again after this
const latin1 = new TextDecoder('latin1');

// Whether this browser can read a response body as it arrives (otherwise the card uses <img>).
export function supported() {
  return typeof ReadableStream !== 'undefined' && typeof Response !== 'undefined'
    && 'body' in Response.prototype && typeof AbortController !== 'undefined';
}

function indexOf(bytes, pattern, from) {
  const last = bytes.length - pattern.length;
  outer: for (let i = from; i <= last; i += 1) {
    for (let j = 0; j < pattern.length; j += 1) if (bytes[i + j] !== pattern[j]) continue outer;
    return i;
  }
  return -1;
}

// Cuts a multipart/x-mixed-replace body into parts: push(chunk) returns the complete parts
// ({headers, data}) it finished. Each part's length is its Content-Length header (the server sends it).
export class PartReader {
  constructor() {
    this.buf = new Uint8Array(0);
    this.need = null;  // the headers of the part whose body is being read, or null while reading headers
  }

  push(chunk) {
    const joined = new Uint8Array(this.buf.length + chunk.length);
    joined.set(this.buf, 0);
    joined.set(chunk, this.buf.length);
    this.buf = joined;
    const parts = [];
    let at = 0;
    for (;;) {
      if (this.need === null) {
        const end = indexOf(this.buf, HEAD_END, at);
        if (end < 0) break;
        const headers = {};
        // The boundary line (and the CRLF before it) come before each part's headers.
        for (const line of latin1.decode(this.buf.subarray(at, end)).split('\r\n')) {
          const colon = line.indexOf(':');
          if (colon > 0 && !line.startsWith('--')) headers[line.slice(0, colon).trim().toLowerCase()] = line.slice(colon + 1).trim();
        }
        at = end + HEAD_END.length;
        const length = Number.parseInt(headers['content-length'], 10);
        if (!Number.isFinite(length) || length < 0) throw new Error(_('a stream part without a Content-Length'));
        this.need = { headers, length };
      }
      if (this.buf.length - at < this.need.length) break;
      parts.push({ headers: this.need.headers, data: this.buf.slice(at, at + this.need.length) });
      at += this.need.length;
      this.need = null;
    }
    this.buf = this.buf.slice(at);
    return parts;
  }
}

// Acknowledgements of one stream: the newest count, with at most one request in flight.
function acker(viewerId, isStopped) {
  const path = `/api/camera/viewers/${encodeURIComponent(viewerId)}/ack`;
  let wanted = 0;
  let sent = 0;
  let inFlight = false;
  let retry = null;
  async function send() {
    if (inFlight || isStopped() || wanted <= sent) return;
    inFlight = true;
    const count = wanted;
    let ok = false;
    try {
      await api('POST', path, { bytes: count });
      sent = Math.max(sent, count);
      ok = true;
    } catch { /* refused (the stream ended: the reader sees that) or not reached: try again shortly */ }
    inFlight = false;
    if (ok) send();  // newer bytes arrived meanwhile: their count goes now
    else if (!isStopped()) { clearTimeout(retry); retry = setTimeout(send, RETRY_ACK_MS); }
  }
  return {
    offer(count) { wanted = Math.max(wanted, count); send(); },
    stop() { clearTimeout(retry); },
    get sent() { return sent; },
  };
}

// Plays the MJPEG stream at `url` (already under the page's robot, with its query) into `img`,
// acknowledging as it reads. `show(figures)` gets {fps, width, height, kbps} as frames arrive,
// `fail(message)` why the stream ended (refused, or broke off). Returns a function that stops it.
export function playAcked(img, url, show, fail) {
  const controller = new AbortController();
  let stopped = false;
  let objectUrl = null;
  let acks = null;
  const arrivals = [];  // [time ms, bytes] of the last few frames
  const isStopped = () => stopped;

  function display(data) {
    const previous = objectUrl;
    objectUrl = URL.createObjectURL(new Blob([data], { type: 'image/jpeg' }));
    img.src = objectUrl;
    if (previous) URL.revokeObjectURL(previous);
    const now = performance.now();
    arrivals.push([now, data.length]);
    while (arrivals.length > 10) arrivals.shift();
    if (arrivals.length < 2) return;
    const span = (now - arrivals[0][0]) / 1000 || 1e-3;
    const counted = arrivals.slice(1);
    const figures = {
      fps: counted.length / span,
      kbps: counted.reduce((sum, [, bytes]) => sum + bytes, 0) * 8 / 1000 / span,
    };
    img.decode().then(() => {
      if (!stopped) show({ ...figures, width: img.naturalWidth, height: img.naturalHeight });
    }).catch(() => { /* a newer frame replaced it first */ });
  }

  async function read() {
    const response = await fetch(url + (url.includes('?') ? '&' : '?') + 'ack=1',
      { cache: 'no-store', signal: controller.signal });
    if (!response.ok) throw await errorFrom(response);
    const viewerId = response.headers.get('X-Camera-Viewer');
    acks = viewerId ? acker(viewerId, isStopped) : null;  // none: the server does not adapt, nothing to say
    if (!response.body) throw new Error(_('this browser cannot read the stream as it arrives'));
    const reader = response.body.getReader();
    const parts = new PartReader();
    let received = 0;
    for (;;) {
      const { done, value } = await reader.read();
      if (done) throw new Error(_('the stream ended'));
      if (stopped) return;
      received += value.length;
      const complete = parts.push(value);
      if (complete.length === 0) continue;
      display(complete[complete.length - 1].data);  // older complete ones are already stale
      if (acks) acks.offer(received);
    }
  }

  read().catch((err) => {
    if (!stopped) fail(err.message || String(err));
  });
  return () => {
    stopped = true;
    controller.abort();
    if (acks) acks.stop();
    if (objectUrl) URL.revokeObjectURL(objectUrl);
    objectUrl = null;
  };
}
