// The replay's diagnostics: the board as the live page showed it at the slider's time (GET
// .../diagnostics?t=, worked out on the server by the live board's own code), drawn by the
// diagnostics page's table (diagnostics/board.js).
import { api } from '../../core/api.js';
import { showBoard } from '../../diagnostics/board.js';
import { newestOnly } from './at.js';
import { _ } from '../../core/i18n.js';

const DIAGNOSTIC_ARRAY = 'diagnostic_msgs/msg/DiagnosticArray';
const MIN_GAP_MS = 150;  // playing: a few boards a second are plenty

// els: { section, table, body, empty, note }.
export function createDiagnostics(recordingId, data, els) {
  const topics = Object.entries(data.topics).filter(([, info]) => info.type === DIAGNOSTIC_ARRAY).map(([t]) => t);
  if (!topics.length) {
    els.note.textContent = _('No diagnostics in this recording (/diagnostics was not recorded).');
    els.table.hidden = true;
    return { show() {} };
  }
  els.note.textContent = _('From %(topics)s.', { topics: topics.join(', ') });
  const ask = newestOnly(
    (t) => api('GET', `/api/recordings/${recordingId}/diagnostics?t=${t}`),
    (board, t) => {
      showBoard(board, { body: els.body, empty: els.empty });
      els.table.dataset.t = String(t);  // the time this board is for (the browser tests wait on it)
    },
    (err) => { els.note.textContent = _('The diagnostics could not be read: %(reason)s', { reason: err.message }); },
    { minGapMs: MIN_GAP_MS });
  return { show: (t) => ask(t) };
}
