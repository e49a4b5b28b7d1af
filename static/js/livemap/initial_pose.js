// Set the robot's initial pose, as RViz's "2D Pose Estimate" does: press where the robot really is
// and drag towards where it faces; AMCL re-seeds from POST /api/maps/<map>/initial_pose, which the
// server publishes on /initialpose. A click without a drag keeps the heading the robot believes it
// has (or east, with no pose), since an operator correcting a position rarely knows a better one.
import { api, ApiError } from '../core/api.js';
import { isDrag, mapYawOfScreen, screenAngle, screenToWorld, wrapAngle } from './geometry.js';
import { degrees, fmt, say } from './readout.js';

export const POSE_MODE = 'pose';
export const POSE_HINT = 'Press where the robot really is and drag the way it faces (a click keeps its heading). '
  + 'Esc cancels.';

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
  say('Setting the initial pose…');
  try {
    const reply = await api('POST', `${mapPath(S.map)}/initial_pose`, body);
    S.lastInitialPose = { request: body, status: 200, reply };
    say(`Initial pose sent on ${reply.topic}: ${fmt(x)}, ${fmt(y)} m, ${degrees(yaw)}.`);
  } catch (err) {
    const refused = err instanceof ApiError;
    S.lastInitialPose = { request: body, status: refused ? err.status : 'failed', reply: refused ? err.reply || {} : {} };
    say(refused ? `Initial pose refused: ${err.message}` : 'Initial pose not sent: the server did not answer.', true);
  }
  redraw();
}

// The gesture's end in pose mode: from press (sx, sy) to release (ex, ey) in canvas pixels.
export function finishPoseGesture(S, sx, sy, ex, ey, livePose, redraw) {
  const [x, y] = screenToWorld(S.geometry, S.view, sx, sy);
  return sendInitialPose(S, x, y, poseYaw(S.geometry, sx, sy, ex, ey, livePose), redraw);
}
