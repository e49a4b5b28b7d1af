// One event stream for all of a browser's rover_web tabs. Browsers allow six HTTP/1.1
// connections per host across all tabs: with a stream per tab, a few open tabs used them up and
// the e-stop's POST waited inside the browser for a free one (issue 15).
//
// The tab that holds the Web Lock NAME leads: it opens one EventSource on the union of every
// tab's channels and relays each event on the BroadcastChannel NAME; the others follow. Web Locks
// and BroadcastChannel rather than a SharedWorker, which Chrome on Android lacks. A closed
// leader's lock goes to the next tab in the lock's queue. A frozen or hung leader keeps its lock,
// so a follower that hears nothing from it for a few seconds steals the lock.
// navigator.locks exists only in secure contexts (https, localhost): over plain http to the
// robot's address every tab keeps a stream of its own, as before.
//
// Each leader has a term, one more than any it heard of. A leader that hung and then resumes
// relays the events it had queued, stale by then: followers go by the newest term they heard and
// ignore older ones.
//
// Messages on the channel, each with the sender's `tab` and `term` (0 from a follower):
//   hello {channels, join}  a tab's channels: on start (join), and in answer to each heartbeat
//   bye                     the tab is going
//   resign                  the leader lost its lock
//   leader {beat, trouble}  the leader's heartbeat, every HEARTBEAT_MS, trouble: its stream is down
//   trouble                 the leader's stream just failed
//   event {channel, data, id}
//   snapshot {to, events}   the current value of each conflated channel, for a tab that joined

import { base } from '../core/api.js';
import { Source, duplicateFilter } from './stream_source.js';

// Per robot: tabs of different robots (/robots/<name>/...) must never share one robot's events.
const NAME = `rover_web-sse${base}`;
// Channels the server puts in its ring (hub.emit) instead of conflating: every event counts, so a
// tab that joins is not handed an old one as if it were new. tests/unit/events/test_ring_channels.py
// checks this against the server's code.
export const RING_CHANNELS = new Set(['scan_code', 'panel_log', 'plot']);
const HEARTBEAT_MS = 1000;
const DEAD_AFTER_MS = 3000;  // plus up to 1.5 s at random, so followers do not all steal at once
const FORGET_AFTER_BEATS = 5;  // a follower that answered none of the last heartbeats is gone
const SHRINK_AFTER_MS = 5000;

// sink: { event(channel, data, id), trouble(), role('leader' | 'follower' | 'own'), live() }; live():
// whether this tab's stream is up, so a leader whose stream is down hands a joining tab nothing
// rather than old values that would look current there.
// Returns { restart() }, for a stream that went silent.
export function openStream(channels, sink) {
  const mine = new Set(channels);
  const seenBefore = duplicateFilter(RING_CHANNELS);
  const deliver = (channel, data, id) => {
    if (mine.has(channel) && !seenBefore(channel, id, data)) sink.event(channel, data, id);
  };
  if (!navigator.locks || typeof BroadcastChannel !== 'function') {
    const source = new Source(deliver, () => sink.trouble());
    source.open(mine);
    sink.role('own');
    return { restart: () => source.open(source.asked) };
  }
  return new SharedStream(mine, deliver, sink).start();
}

class SharedStream {
  constructor(mine, deliver, sink) {
    this.tab = `${Date.now().toString(36)}-${Math.random().toString(36).slice(2)}`;
    this.mine = mine;
    this.deliver = deliver;
    this.sink = sink;
    this.bus = new BroadcastChannel(NAME);
    this.tabs = new Map();    // every other tab -> { channels, beat it last said hello at }
    this.latest = new Map();  // conflated channel -> its newest event, for tabs that join
    this.beat = 0;            // the leader's heartbeat count, as far as this tab knows
    this.term = 0;            // the newest term heard of
    this.myTerm = 0;          // this tab's term while it leads, else 0
    this.current = null;      // { term, tab } of the leader this tab listens to
    this.lastId = '';         // the newest event id relayed: where this tab resumes if it leads
    this.heardAt = performance.now();
    this.checkedAt = performance.now();
    this.deadAfter = DEAD_AFTER_MS + Math.random() * 1500;
    this.source = null;       // the EventSource, while this tab leads
    this.grant = null;        // the lock grant this tab leads under
    this.queued = null;       // the AbortController of this tab's waiting lock request
    this.shrinkSince = 0;
    this.growTimer = null;
  }

  start() {
    this.bus.onmessage = (ev) => this.receive(ev.data);
    this.sink.role('follower');
    this.hello(true);
    this.campaign(false);
    setInterval(() => this.check(), 500);
    setInterval(() => this.heartbeat(), HEARTBEAT_MS);
    addEventListener('pagehide', () => {
      this.say({ type: 'bye' });
      if (this.source) this.source.close();  // frees the server's thread now, not when the tab is gone
    });
    addEventListener('pageshow', (ev) => {
      if (!ev.persisted) return;  // back from the back-forward cache
      this.heardAt = performance.now();
      if (this.source) {
        this.myTerm = this.term += 1;  // the others heard this tab's bye
        this.current = { term: this.myTerm, tab: this.tab };
        this.source.open(this.union());
      }
      this.hello(true);
    });
    return { restart: () => { if (this.source) this.source.open(this.source.asked); } };
  }

  say(message) { this.bus.postMessage({ ...message, tab: this.tab, term: this.myTerm }); }

  hello(join) { this.say({ type: 'hello', channels: [...this.mine], join }); }

  // --- who leads ---

  // One lock request at a time per tab: a queued one, or a steal that replaces it.
  campaign(steal) {
    if (!steal && this.queued) return;
    const withdraw = new AbortController();
    if (!steal) this.queued = withdraw;
    let grant = null;
    const granted = () => new Promise((release) => {
      grant = { release };
      this.grant = grant;
      if (this.queued === withdraw) this.queued = null;
      this.lead();
    });
    navigator.locks.request(NAME, steal ? { steal: true } : { signal: withdraw.signal }, granted)
      .catch(() => { /* AbortError: another tab stole the lock, or this tab withdrew the request */ })
      .then(() => {
        if (this.queued === withdraw) this.queued = null;
        if (!grant) return;
        grant.release();
        if (this.grant !== grant) return;  // this tab holds a newer grant
        this.grant = null;
        this.follow();
        this.campaign(false);
      });
  }

  // A follower that heard nothing for seconds: the leader is frozen or hung, and still holds the
  // lock. A tab whose own timers were held back (hidden, frozen, asleep) cannot tell, so it waits.
  check() {
    const now = performance.now();
    const slept = now - this.checkedAt > 2000;
    this.checkedAt = now;
    if (slept) this.heardAt = Math.max(this.heardAt, now - DEAD_AFTER_MS / 2);
    if (this.source || now - this.heardAt < this.deadAfter) return;
    this.heardAt = now;  // one steal per silence
    if (this.queued) this.queued.abort();
    this.queued = null;
    this.campaign(true);
  }

  lead() {
    if (this.source) return;
    this.myTerm = this.term += 1;
    this.current = { term: this.myTerm, tab: this.tab };
    this.source = new Source((ch, data, id) => this.relay(ch, data, id), () => this.trouble(), this.lastId);
    this.source.open(this.union());
    this.shrinkSince = 0;
    this.sink.role('leader');
    this.heartbeat();
  }

  follow() {
    if (!this.source) return;
    this.say({ type: 'resign' });
    this.stepDown(this.myTerm);
    this.myTerm = 0;
    this.lastId = this.source.lastId;
    this.source.close();
    this.source = null;
    this.heardAt = performance.now();
    this.sink.role('follower');
  }

  // --- leading ---

  relay(channel, data, id) {
    this.remember(channel, data, id);
    this.say({ type: 'event', channel, data, id });
    this.deliver(channel, data, id);
  }

  trouble() {
    this.say({ type: 'trouble' });
    this.sink.trouble();
  }

  heartbeat() {
    if (!this.source) return;
    this.beat += 1;
    for (const [tab, t] of this.tabs) if (this.beat - t.beat > FORGET_AFTER_BEATS) this.tabs.delete(tab);
    this.say({ type: 'leader', beat: this.beat, trouble: this.source.troubled });
    this.reconcile();
  }

  union() {
    const all = new Set(['status', ...this.mine]);
    for (const t of this.tabs.values()) for (const ch of t.channels) all.add(ch);
    return all;
  }

  // More channels: reopen now, a tab is waiting for them (the server starts a stream with the
  // current value of each). Fewer: only after a while, so a tab that reloads does not cost two.
  reconcile() {
    if (!this.source) return;
    const want = this.union();
    const open = this.source.asked;
    const now = performance.now();
    if ([...want].some((ch) => !open.has(ch))) this.reopen(want);
    else if (open.size === want.size) this.shrinkSince = 0;
    else if (!this.shrinkSince) this.shrinkSince = now;
    else if (now - this.shrinkSince > SHRINK_AFTER_MS) this.reopen(want);
  }

  reopen(channels) {
    this.shrinkSince = 0;
    this.source.open(channels);
  }

  welcome(tab, channels) {
    if (this.sink.live && !this.sink.live()) return;
    const events = [...this.latest.values()].filter((e) => channels.includes(e.channel))
      .sort((a, b) => Number(a.id) - Number(b.id));
    if (events.length) this.say({ type: 'snapshot', to: tab, events });
  }

  // --- everyone ---

  remember(channel, data, id) {
    if (id) this.lastId = id;
    if (!RING_CHANNELS.has(channel)) this.latest.set(channel, { channel, data, id });
  }

  // After the leader of `term` stepped down, only a newer term is listened to ('~' sorts after
  // every tab id).
  stepDown(term) { this.current = { term, tab: '~' }; }

  // Whether a leader's message comes from the newest leader heard of (ties go to the larger tab id).
  accept(m) {
    const c = this.current;
    if (c && (m.term < c.term || (m.term === c.term && m.tab < c.tab))) return false;
    this.current = { term: m.term, tab: m.tab };
    return true;
  }

  receive(m) {
    this.term = Math.max(this.term, m.term);
    const fromCurrent = this.current && m.term === this.current.term && m.tab === this.current.tab;
    if (m.type === 'hello') {
      const known = this.tabs.has(m.tab);
      this.tabs.set(m.tab, { channels: new Set(m.channels), beat: this.beat });
      if (!this.source) return;
      if (m.join || !known) this.welcome(m.tab, m.channels);
      clearTimeout(this.growTimer);  // tabs answer a heartbeat together: one reopen for all of them
      this.growTimer = setTimeout(() => this.reconcile(), 50);
    } else if (m.type === 'bye' || m.type === 'resign') {
      this.tabs.delete(m.tab);
      if (fromCurrent && !this.source) this.stepDown(m.term);
    } else if (this.source) {
      // A leader whose lock this tab took, and that has not noticed yet: this tab's own stream
      // carries the same events, newer.
      if (m.type === 'leader') this.beat = Math.max(this.beat, m.beat);
    } else if (!this.accept(m)) {
      // an older leader's queued messages
    } else if (m.type === 'leader') {
      this.heardAt = performance.now();
      this.beat = Math.max(this.beat, m.beat);
      if (m.trouble) this.sink.trouble();
      this.hello(false);
    } else if (m.type === 'trouble') {
      this.heardAt = performance.now();
      this.sink.trouble();
    } else if (m.type === 'event') {
      this.heardAt = performance.now();
      this.remember(m.channel, m.data, m.id);
      this.deliver(m.channel, m.data, m.id);
    } else if (m.type === 'snapshot' && m.to === this.tab) {
      this.heardAt = performance.now();
      for (const e of m.events) this.deliver(e.channel, e.data, e.id);
    }
  }
}
