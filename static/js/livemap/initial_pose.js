// Set the robot's initial pose, as RViz's "2D Pose Estimate" does: press where the robot really is
// and drag towards where it faces; AMCL re-seeds from POST /api/maps/<map>/initial_pose, which the
// server publishes on /initialpose. A click without a drag keeps the heading the robot believes it
// has (or east, with no pose), since an operator correcting a position rarely knows a better one.
import { api, ApiError } from '../core/api.js';
import { isDrag, mapYawOfScreen, screenAngle, screenToWorld, wrapAngle } from './geometry.js';
import { degrees, metres, say } from './readout.js';
import { _ } from '../core/i18n.js';

export const POSE_MODE = 'pose';
export const POSE_HINT = _(
  'Press where the robot really is and drag the way it faces (a click keeps its heading). Esc cancels.');

const mapPath = (name) => `/api/maps/${encodeURIComponent(name)}`;

export function poseYaw(g, sx, sy, ex, ey, pose) {
  if (isDrag(sx, sy, ex, ey)) return wrapAngle(mapYawOfScreen(g, screenAngle(sx, sy, ex, ey)));
  return pose ? wrapAngle(pose.yaw) : 0;
}

// S.lastInitialPose records each request and how it ended, as S.lastGoal does for goals: the
// browser tests wait on it.
export async function sendInitialPose(S, x, y, yaw, redraw) {
  const body = { x, y, yaw };
  S.lastInitialPose = { request: body, status: 'sending' };
  say(_('Setting the initial pose…'));
  try {
    const reply = await api('POST', `${mapPath(S.map)}/initial_pose`, body);
    S.lastInitialPose = { request: body, status: 200, reply };
    say(_('Initial pose sent on %(topic)s: %(position)s, %(heading)s.',
      { topic: reply.topic, position: metres(x, y), heading: degrees(yaw) }));
  } catch (err) {
    const refused = err instanceof ApiError;
    S.lastInitialPose = { request: body, status: refused ? err.status : 'failed', reply: refused ? err.reply || {} : {} };
    say(refused ? _('Initial pose refused: %(reason)s', { reason: err.message })
      : _('Initial pose not sent: the server did not answer.'), true);
  }
  redraw();
}

// The gesture's end in pose mode: from press (sx, sy) to release (ex, ey) in canvas pixels.
export function finishPoseGesture(S, sx, sy, ex, ey, livePose, redraw) {
  const [x, y] = screenToWorld(S.geometry, S.view, sx, sy);
  return sendInitialPose(S, x, y, poseYaw(S.geometry, sx, sy, ex, ey, livePose), redraw);
}
