// The one way pages call rover_web's JSON API. The server refuses with a 4xx/5xx and
// {"error": code, "message": text} (rover_web/http.py), so callers can show err.message as it is.
// Something else may answer instead (a proxy's HTML error page): that still becomes an ApiError
// with a message naming the status, never a JSON SyntaxError.
// A request that got no answer rejects with fetch's own TypeError, not an ApiError: pages say
// "refused" and "not reached" differently, and `instanceof ApiError` tells them apart.

// The page's robot: /robots/<name> when it was served under a robot's prefix (several robots),
// '' otherwise. Every path a page asks for is under it, so a page drives the robot it shows.
import { _ } from './i18n.js';

export const base = (typeof document !== 'undefined' && document.body && document.body.dataset.base) || '';

// Where the app itself is mounted, before any robot's prefix: routes for every robot at once
// (POST /api/estop/all) and the robots' own URLs start here. '' when served at the host's root.
export const appRoot = (typeof document !== 'undefined' && document.body && document.body.dataset.appRoot) || '';

// A root-relative path ('/api/teleop') under the page's robot, or with { root: true } under the
// app's root whichever robot the page shows.
export const at = (path, { root = false } = {}) => (path.startsWith('/') ? (root ? appRoot : base) + path : path);

export class ApiError extends Error {
  constructor(status, code, message, reply = null) {
    super(message);
    this.name = 'ApiError';
    this.status = status;  // the HTTP status
    this.code = code;      // the server's "error" code, or null when it did not send one
    this.reply = reply;    // the parsed JSON answer, or null
  }
}

// null for an empty body (204); undefined when the body is there but is not JSON.
async function readJSON(response) {
  const text = await response.text();
  if (!text.trim()) return null;
  try { return JSON.parse(text); } catch { return undefined; }
}

// The ApiError for a non-2xx response. Exported for callers that must make their own fetch,
// e.g. to probe a stream URL whose success body must not be read to its end.
export async function errorFrom(response) {
  let reply = null;
  try { reply = (await readJSON(response)) ?? null; } catch { /* the body broke off: the status is enough */ }
  const said = (key) => (reply && typeof reply[key] === 'string' && reply[key]) || null;
  const status = `HTTP ${response.status}${response.statusText ? ` ${response.statusText}` : ''}`;
  return new ApiError(response.status, said('error'), said('message') || status, reply);
}

// body: an object to send as JSON, or a string that already is JSON text (an uploaded file),
// sent as it is so the server, not the page, judges it. null, like undefined, sends no body:
// fetch refuses any body on a GET. options.root: the path is the app's, not the page robot's (at()).
export async function api(method, url, body, options = {}) {
  const init = { method, headers: { Accept: 'application/json' } };
  if (body !== undefined && body !== null) {
    init.headers['Content-Type'] = 'application/json';
    init.body = typeof body === 'string' ? body : JSON.stringify(body);
  }
  const response = await fetch(at(url, options), init);
  if (!response.ok) throw await errorFrom(response);
  const reply = await readJSON(response);
  if (reply === undefined) {
    throw new ApiError(response.status, null, _('HTTP %(status)s: the answer is not JSON', { status: response.status }));
  }
  return reply;
}
