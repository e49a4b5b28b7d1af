// Everything this page says to and hears from the server: goal requests, and the pose, goal, plan
// and live_map channels of the page's one event stream (live.js).
import { api, ApiError } from '../core/api.js';
import { on, onServerState } from '../live/live.js';
import { geometryOfLiveMap } from './geometry.js';
import { degrees, metres, say } from './readout.js';
import { _ } from '../core/i18n.js';

const mapPath = (name) => `/api/maps/${encodeURIComponent(name)}`;
export const mapPageUrl = (name) => `/livemap/${encodeURIComponent(name)}`;
// The version in the URL makes a changed live grid a new image, never a cached old one.
export const mapImageUrl = (name, version) => `${mapPath(name)}/image?v=${version}`;

const goalOf = (g) => ({ x: g.x, y: g.y, yaw: g.yaw, frame_id: g.frame_id });

// S.lastGoal records each request and how it ended: 'sending', the HTTP status, or 'failed' when
// no answer came; the browser tests wait on it.
export async function sendGoal(S, x, y, yaw, what, redraw) {
  const body = { x, y, yaw };
  S.lastGoal = { request: body, status: 'sending' };
  say(_('Sending %(what)s…', { what }));
  try {
    const reply = await api('POST', `${mapPath(S.map)}/goal`, body);
    S.lastGoal = { request: body, status: 200, reply };  // api() resolves only on 2xx; this route answers 200
    S.goal = goalOf(reply.goal);
    say(_('Goal sent: %(what)s (%(position)s, %(heading)s).', { what, position: metres(x, y), heading: degrees(yaw) }));
  } catch (err) {
    if (err instanceof ApiError) {
      S.lastGoal = { request: body, status: err.status, reply: err.reply || {} };
      say(_('Goal refused: %(reason)s', { reason: err.message }), true);
    } else {
      S.lastGoal = { request: body, status: 'failed' };
      say(_('Goal not sent: the server did not answer.'), true);
    }
  }
  redraw();
}

// Keeps S current from the event stream. What the page does about it comes as callbacks:
// redraw(), robotMoved() (a live pose arrived), mapListed(m) for every live_map event, and
// newImage(url) when this page's own live grid changed.
export function follow(S, { redraw, robotMoved, mapListed, newImage }) {
  on('pose', (p) => {
    S.pose = { x: p.x, y: p.y, yaw: p.yaw, frame_id: p.frame_id, stale: p.stale, pixels: p.pixels[S.map] || null };
    if (!p.stale) robotMoved();
    redraw();
  });
  on('goal', (g) => {
    S.goal = goalOf(g);
    redraw();
  });
  on('plan', (plan) => {
    S.plan = plan;
    redraw();
  });
  on('live_map', (m) => {
    mapListed(m);
    if (m.name !== S.map || m.version === S.version) return;
    S.version = m.version;
    S.geometry = geometryOfLiveMap(m);
    newImage(mapImageUrl(m.name, m.version));
    redraw();
  });
  onServerState((state) => {
    S.serverState = state;
    redraw();
  });
}
