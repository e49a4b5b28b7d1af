// The EventSource under live.js, used by the one tab that holds the browser's stream (see
// shared_stream.js) or by every tab where tabs cannot share one.

// Opening again (more channels, a silent stream) passes the last event id, so the server replays
// the ring events (scan_code, panel_log) sent in between instead of losing them; the conflated
// channels come back as a snapshot either way.
import { at } from '../core/api.js';

export class Source {
  constructor(onEvent, onTrouble, lastId = '') {
    this.onEvent = onEvent;      // (channel, data, id)
    this.onTrouble = onTrouble;  // () on every error, before any retry
    this.lastId = lastId;
    this.asked = new Set();      // the channels asked for
    this.channels = new Set();   // those of them the stream carries
    this.refused = new Set();    // names the server does not know
    this.troubled = false;       // an error since the last event
    this.es = null;
    this.retryTimer = null;
  }

  open(channels) {
    this.close();
    this.asked = new Set(channels);
    this.channels = new Set([...this.asked].filter((ch) => !this.refused.has(ch)));
    const url = this.url();
    const es = new EventSource(url);
    for (const ch of this.channels) {
      es.addEventListener(ch, (ev) => {
        this.troubled = false;
        if (ev.lastEventId) this.lastId = ev.lastEventId;
        this.onEvent(ch, ev.data, ev.lastEventId);
      });
    }
    es.onerror = () => {
      if (es !== this.es) return;
      this.troubled = true;
      this.onTrouble();
      // A CLOSED EventSource (e.g. the server answered with an error page) never retries by itself.
      if (es.readyState === EventSource.CLOSED) this.retryAfterRefusal(es, url);
    };
    this.es = es;
  }

  url() {
    const since = this.lastId ? `&lastEventId=${encodeURIComponent(this.lastId)}` : '';
    return at(`/api/events?channels=${[...this.channels].join(',')}${since}`);
  }

  // A shared stream asks for every tab's channels, so one tab asking for a name this server does
  // not have (a page older than the server) would stop the stream of every tab: that name is
  // dropped instead. EventSource hides the server's answer, so it is asked for once more.
  async retryAfterRefusal(es, url) {
    const abort = new AbortController();
    const giveUp = setTimeout(() => abort.abort(), 3000);
    try {
      const res = await fetch(url, { signal: abort.signal, headers: { Accept: 'application/json' } });
      const reply = res.status === 400 ? await res.json() : null;
      const named = reply && reply.error === 'unknown_channel' && /unknown channel\(s\) ([^;]*);/.exec(reply.message);
      for (const ch of named ? named[1].split(', ') : []) {
        console.warn(`the server has no event channel ${ch}; the live stream goes on without it`);
        this.refused.add(ch);
      }
    } catch { /* the server is away: just retry */ } finally {
      clearTimeout(giveUp);
      abort.abort();  // a stream that did open is not read
    }
    if (this.es === es) this.retryTimer = setTimeout(() => this.open(this.asked), 1000);
  }

  close() {
    clearTimeout(this.retryTimer);
    if (this.es) this.es.close();
    this.es = null;
  }
}

// True for an event seen already: a reopened stream repeats every channel's current value, and
// while the stream changes hands two tabs may relay the same events for a moment. An id alone is
// not enough, because a restarted server counts ids from 1 again; the same id with the same data is.
export function duplicateFilter(ringChannels) {
  const recent = new Map();  // channel -> Map(id -> data), oldest first
  return (channel, id, data) => {
    if (!id) return false;
    let seen = recent.get(channel);
    if (!seen) recent.set(channel, seen = new Map());
    if (seen.get(id) === data) return true;
    seen.set(id, data);
    // A conflated channel only ever repeats its newest value; ring events can come back as a run.
    const keep = ringChannels.has(channel) ? 64 : 1;
    while (seen.size > keep) seen.delete(seen.keys().next().value);
    return false;
  };
}
