// LiveMap's Nav2 panel: goals as NavigateToPose (or on the goal topic, as the server says:
// goal_via), routes of waypoints as FollowWaypoints or NavigateThroughPoses, the running goal's
// feedback and result, cancel, and Nav2's servers' lifecycle states. Everything comes from the
// `nav2` channel (at a bounded rate) and GET /api/nav2's state in #nav2-data; window.nav2State
// mirrors what is shown, for the browser tests.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';

const $ = (id) => document.getElementById(id);
const fmt = (v, digits = 1) => (Number.isFinite(v) ? v.toFixed(digits) : '—');

function seconds(s) {
  if (!Number.isFinite(s)) return '—';
  const m = Math.floor(s / 60);
  return m ? `${m} min ${Math.round(s % 60)} s` : `${s.toFixed(1)} s`;
}

const KINDS = { to_pose: 'NavigateToPose', through_poses: 'NavigateThroughPoses', follow_waypoints: 'FollowWaypoints' };
const ENDED = new Set(['succeeded', 'canceled', 'aborted', 'unknown']);

export function attachNav2(S, { redraw, say }) {
  const panel = $('nav2');
  S.nav2 = JSON.parse($('nav2-data').textContent);
  S.route = [];  // [{x, y, yaw, name}], the route being made
  S.lastNav2 = null;

  const running = () => S.nav2.goal && !ENDED.has(S.nav2.goal.status);

  function render() {
    const n = S.nav2;
    panel.dataset.via = n.goal_via;
    panel.dataset.available = n.available ? 'yes' : 'no';
    const missing = $('nav2-missing');
    missing.hidden = !n.missing;
    if (n.missing) missing.textContent = `Nav2's actions are off: ${n.missing.message}`;
    $('nav2-via').textContent = n.goal_via === 'action'
      ? `Goals go to ${n.servers.to_pose.action} (NavigateToPose).`
      : `Goals go to the goal topic${n.available ? ' (no NavigateToPose server answers yet)' : ''}.`;
    const g = n.goal;
    const f = n.feedback;
    $('nav2-goal').textContent = g ? `${KINDS[g.kind]} · ${g.poses.length} pose${g.poses.length > 1 ? 's' : ''}` : '—';
    $('nav2-status').textContent = g ? g.status + (g.cancel ? ` (cancel: ${g.cancel.by})` : '') : '—';
    $('nav2-status').dataset.status = g ? g.status : '';
    const moving = f && g && g.kind !== 'follow_waypoints';
    $('nav2-distance').textContent = moving ? `${fmt(f.distance_remaining_m, 2)} m` : '—';
    $('nav2-eta').textContent = moving ? seconds(f.estimated_time_remaining_s) : '—';
    $('nav2-time').textContent = moving ? seconds(f.navigation_time_s) : '—';
    $('nav2-recoveries').textContent = moving ? String(f.number_of_recoveries) : '—';
    let waypoint = '—';
    if (f && g && g.kind === 'follow_waypoints') waypoint = `${f.current_waypoint + 1} of ${g.poses.length}`;
    if (f && g && g.kind === 'through_poses') waypoint = `${f.number_of_poses_remaining} pose(s) left`;
    $('nav2-waypoint').textContent = waypoint;
    const r = n.result;
    let result = '—';
    if (r) {
      result = r.status;
      if (r.error_code) result += ` · error ${r.error_code}${r.error_name ? ` ${r.error_name}` : ''}`;
      if (r.error_msg) result += ` · ${r.error_msg}`;
      if (r.missed_waypoints && r.missed_waypoints.length) {
        result += ` · missed ${r.missed_waypoints.map((m) => `${m.index + 1} (${m.error_name || m.error_code})`).join(', ')}`;
      }
    }
    $('nav2-result').textContent = result;
    $('nav2-result').dataset.status = r ? r.status : '';
    $('nav2-cancel').disabled = !running();
    renderRoute();
    renderServers();
    window.nav2State = { ...n, route: S.route.map((p) => ({ ...p })), lastNav2: S.lastNav2 };
  }

  function renderRoute() {
    const list = $('nav2-route');
    list.replaceChildren(...S.route.map((p, i) => {
      const li = document.createElement('li');
      li.textContent = `${p.name || `point ${i + 1}`} (${fmt(p.x, 2)}, ${fmt(p.y, 2)})`;
      return li;
    }));
    $('nav2-route-empty').hidden = S.route.length > 0;
    $('nav2-route-send').disabled = !S.route.length || !S.nav2.available;
    $('nav2-route-clear').disabled = !S.route.length;
  }

  function renderServers() {
    const list = $('nav2-servers');
    list.replaceChildren(...S.nav2.lifecycle.map((node) => {
      const li = document.createElement('li');
      li.dataset.node = node.node;
      li.dataset.state = node.state;
      const name = document.createElement('span');
      name.textContent = node.node;
      const state = document.createElement('b');
      state.textContent = node.state;
      li.append(name, ' ', state);
      return li;
    }));
  }

  // A request and how it ended ('sending', the HTTP status, 'failed'), as LiveMap's goals record theirs.
  async function post(path, body, what) {
    S.lastNav2 = { path, request: body, status: 'sending' };
    say(`Sending ${what}…`);
    try {
      const reply = await api('POST', path, body);
      S.lastNav2 = { path, request: body, status: 200, reply };
      return reply;
    } catch (err) {
      if (err instanceof ApiError) {
        S.lastNav2 = { path, request: body, status: err.status, reply: err.reply || {} };
        say(`${what} refused: ${err.message}`, true);
      } else {
        S.lastNav2 = { path, request: body, status: 'failed' };
        say(`${what} not sent: the server did not answer.`, true);
      }
      return null;
    } finally {
      render();
    }
  }

  $('nav2-cancel').addEventListener('click', async () => {
    if (await post('/api/nav2/cancel', {}, 'Cancel')) say('Cancel asked of Nav2.');
  });
  $('nav2-route-clear').addEventListener('click', () => { S.route = []; render(); redraw(); });
  $('nav2-route-send').addEventListener('click', async () => {
    const mode = $('nav2-route-mode').value;
    const poses = S.route.map(({ x, y, yaw }) => ({ x, y, yaw }));
    const reply = await post('/api/nav2/route', { map: S.map, mode, poses }, `the route (${poses.length} poses)`);
    if (reply) {
      say(`Route sent: ${KINDS[reply.goal.kind]} through ${poses.length} poses.`);
      S.route = [];
      render();
      redraw();
    }
  });
  on('nav2', (state) => { S.nav2 = state; render(); redraw(); });
  render();

  return {
    via: () => S.nav2.goal_via,
    addToRoute(p) {
      S.route.push({ x: p.x, y: p.y, yaw: p.yaw || 0, name: p.name || '' });
      say(`Route: ${S.route.length} point${S.route.length > 1 ? 's' : ''}.`);
      render();
      redraw();
    },
    async sendGoal(x, y, yaw, what) {
      const body = { x, y, yaw };
      S.lastGoal = { request: body, status: 'sending' };
      const reply = await post('/api/nav2/goal', { map: S.map, ...body }, what);
      S.lastGoal = { request: body, status: S.lastNav2.status, reply: S.lastNav2.reply };
      if (reply) {
        const p = reply.goal.poses[0];
        S.goal = { x: p.x, y: p.y, yaw: p.yaw, frame_id: reply.goal.frame_id };
        say(`Goal sent to Nav2: ${what} (${fmt(x, 2)}, ${fmt(y, 2)} m).`);
      }
      redraw();
    },
  };
}
