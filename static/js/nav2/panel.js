// LiveMap's Nav2 panel: goals as NavigateToPose (or on the goal topic, as the server says:
// goal_via), routes of waypoints as FollowWaypoints or NavigateThroughPoses, the running goal's
// feedback and result, cancel, and Nav2's servers' lifecycle states. Everything comes from the
// `nav2` channel (at a bounded rate) and GET /api/nav2's state in #nav2-data; window.nav2State
// mirrors what is shown, for the browser tests.
import { api, ApiError } from '../core/api.js';
import { on } from '../live/live.js';
import { _, ngettext, formatNumber, formatUnit, said } from '../core/i18n.js';

const $ = (id) => document.getElementById(id);
const fmt = (v, digits = 1) => (Number.isFinite(v) ? formatNumber(v, digits) : '—');

function seconds(s) {
  if (!Number.isFinite(s)) return '—';
  const m = Math.floor(s / 60);
  return m ? `${formatUnit(m, 'min')} ${formatUnit(Math.round(s % 60), 's')}` : formatUnit(s, 's', 1);
}

// The action's states as Nav2 reports them (rover_web/nav2), in the page's language.
const STATUS_WORDS = {
  sending: _('sending'), sent: _('sent'), accepted: _('accepted'), executing: _('executing'), canceling: _('canceling'),
  succeeded: _('succeeded'), canceled: _('canceled'), aborted: _('aborted'), unknown: _('unknown'),
};
const statusWord = (s) => STATUS_WORDS[s] || s;

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
    if (n.missing) missing.textContent = _("Nav2's actions are off: %(reason)s", { reason: said(n.missing, 'message') });
    $('nav2-via').textContent = n.goal_via === 'action'
      ? _('Goals go to %(action)s (NavigateToPose).', { action: n.servers.to_pose.action })
      : n.available ? _('Goals go to the goal topic (no NavigateToPose server answers yet).') : _('Goals go to the goal topic.');
    const g = n.goal;
    const f = n.feedback;
    $('nav2-goal').textContent = g ? `${KINDS[g.kind]} · ${ngettext('%(num)d pose', '%(num)d poses', g.poses.length)}` : '—';
    $('nav2-status').textContent = g ? statusWord(g.status) + (g.cancel ? ` ${_('(cancel: %(name)s)', { name: g.cancel.by })}` : '') : '—';
    $('nav2-status').dataset.status = g ? g.status : '';
    const moving = f && g && g.kind !== 'follow_waypoints';
    $('nav2-distance').textContent = moving ? formatUnit(f.distance_remaining_m, 'm', 2) : '—';
    $('nav2-eta').textContent = moving ? seconds(f.estimated_time_remaining_s) : '—';
    $('nav2-time').textContent = moving ? seconds(f.navigation_time_s) : '—';
    $('nav2-recoveries').textContent = moving ? formatNumber(f.number_of_recoveries) : '—';
    let waypoint = '—';
    if (f && g && g.kind === 'follow_waypoints') waypoint = _('%(n)d of %(total)d', { n: f.current_waypoint + 1, total: g.poses.length });
    if (f && g && g.kind === 'through_poses') {
      waypoint = ngettext('%(num)d pose left', '%(num)d poses left', f.number_of_poses_remaining);
    }
    $('nav2-waypoint').textContent = waypoint;
    const r = n.result;
    let result = '—';
    if (r) {
      result = statusWord(r.status);
      if (r.error_code) result += ` · ${_('error %(code)s', { code: r.error_code })}${r.error_name ? ` ${r.error_name}` : ''}`;
      if (r.error_msg) result += ` · ${r.error_msg}`;
      if (r.missed_waypoints && r.missed_waypoints.length) {
        const missed = r.missed_waypoints.map((m) => `${m.index + 1} (${m.error_name || m.error_code})`).join(', ');
        result += ` · ${_('missed %(waypoints)s', { waypoints: missed })}`;
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
      const name = p.name || _('point %(n)d', { n: i + 1 });  // a call of its own: Babel misses one nested in another
      li.textContent = _('%(name)s (%(x)s, %(y)s)', { name, x: fmt(p.x, 2), y: fmt(p.y, 2) });
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
      state.textContent = node.state === 'unknown' ? _('unknown') : node.state;  // lifecycle states stay ROS's words
      li.append(name, ' ', state);
      return li;
    }));
  }

  // A request and how it ended ('sending', the HTTP status, 'failed'), as LiveMap's goals record theirs.
  async function post(path, body, what) {
    S.lastNav2 = { path, request: body, status: 'sending' };
    say(_('Sending %(what)s…', { what }));
    try {
      const reply = await api('POST', path, body);
      S.lastNav2 = { path, request: body, status: 200, reply };
      return reply;
    } catch (err) {
      if (err instanceof ApiError) {
        S.lastNav2 = { path, request: body, status: err.status, reply: err.reply || {} };
        say(_('%(what)s refused: %(reason)s', { what, reason: err.message }), true);
      } else {
        S.lastNav2 = { path, request: body, status: 'failed' };
        say(_('%(what)s not sent: the server did not answer.', { what }), true);
      }
      return null;
    } finally {
      render();
    }
  }

  $('nav2-cancel').addEventListener('click', async () => {
    if (await post('/api/nav2/cancel', {}, _('Cancel'))) say(_('Cancel asked of Nav2.'));
  });
  $('nav2-route-clear').addEventListener('click', () => { S.route = []; render(); redraw(); });
  $('nav2-route-send').addEventListener('click', async () => {
    const mode = $('nav2-route-mode').value;
    const poses = S.route.map(({ x, y, yaw }) => ({ x, y, yaw }));
    const reply = await post('/api/nav2/route', { map: S.map, mode, poses }, 
      ngettext('the route (%(num)d pose)', 'the route (%(num)d poses)', poses.length));
    if (reply) {
      say(ngettext('Route sent: %(kind)s through %(num)d pose.', 'Route sent: %(kind)s through %(num)d poses.', poses.length,
        { kind: KINDS[reply.goal.kind] }));
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
      say(ngettext('Route: %(num)d point.', 'Route: %(num)d points.', S.route.length));
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
        const position = _('%(x)s, %(y)s m', { x: fmt(x, 2), y: fmt(y, 2) });
        say(_('Goal sent to Nav2: %(what)s (%(position)s).', { what, position }));
      }
      redraw();
    },
  };
}
