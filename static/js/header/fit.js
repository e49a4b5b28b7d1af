// The bar on top of every page stays one line and never hides anything: what does not fit goes
// into the menu, in this order: the signed-in user, nav links (the last first), then the bar gets
// tighter (header.css: squeeze-1 ... squeeze-3), then the Display menu and last the robot selector
// join the menu. The
// e-stop and "Stop all" never leave the bar. It fits again whenever the window or anything in the
// bar changes size (a pill's word, the e-stop's state, a longer robot name).
import { _ } from '../core/i18n.js';

const bar = document.getElementById('topbar');
const menu = document.getElementById('topbar-menu');

const SQUEEZES = 3;

function setup() {
  const panel = menu.querySelector('.topbar-menu-panel');
  const summary = menu.querySelector('summary');
  const label = menu.querySelector('.menu-label');
  const menuNav = menu.querySelector('.menu-nav');
  const menuMore = menu.querySelector('.menu-more');
  const nav = bar.querySelector(':scope > .nav');
  const links = [...nav.querySelectorAll('a')];
  const user = bar.querySelector(':scope > .whoami');
  const robot = bar.querySelector(':scope > .robot-select');
  const display = bar.querySelector(':scope > .display-menu');
  const userAnchor = document.createComment('user');
  const robotAnchor = document.createComment('robot');
  const displayAnchor = document.createComment('display');
  if (user) user.before(userAnchor);
  if (robot) robot.before(robotAnchor);
  if (display) display.before(displayAnchor);

  // The steps, in the order they are taken; apply(k) takes the first k, from a clean bar.
  const steps = [
    ...(user ? [{ kind: 'user' }] : []),
    ...links.map((_, i) => ({ kind: 'link', index: links.length - 1 - i })),
    ...Array.from({ length: SQUEEZES }, (_, i) => ({ kind: 'squeeze', level: i + 1 })),
    ...(display ? [{ kind: 'display' }] : []),
    ...(robot ? [{ kind: 'robot' }] : []),
  ];

  // linksBack: how many of the links taken out come back into the bar (the first pages, which
  // went last), once the steps after them made room.
  function apply(k, linksBack = 0) {
    const linkSteps = steps.slice(0, k).filter((s) => s.kind === 'link');
    const back = new Set(linkSteps.slice(linkSteps.length - linksBack));
    const taken = steps.slice(0, k).filter((s) => !back.has(s));
    const moved = new Set(taken.filter((s) => s.kind === 'link').map((s) => s.index));
    links.forEach((a, i) => (moved.has(i) ? menuNav : nav).append(a));
    nav.hidden = moved.size === links.length;
    const userOut = taken.some((s) => s.kind === 'user');
    const robotOut = taken.some((s) => s.kind === 'robot');
    const displayOut = taken.some((s) => s.kind === 'display');
    if (user) (userOut ? menuMore.append(user) : userAnchor.after(user));
    if (display) (displayOut ? menuMore.append(display) : displayAnchor.after(display));
    if (robot) (robotOut ? menuMore.prepend(robot) : robotAnchor.after(robot));
    const squeeze = taken.filter((s) => s.kind === 'squeeze').length;
    for (let level = 1; level <= SQUEEZES; level += 1) bar.classList.toggle(`squeeze-${level}`, level <= squeeze);
    const any = moved.size > 0 || userOut || robotOut || displayOut;
    menu.hidden = !any;
    if (!any) menu.open = false;
    // "More" while some pages are still in the bar, "Menu" once they all are in it.
    label.textContent = moved.size && moved.size < links.length ? _('More') : _('Menu');
  }

  // In-flow items all end inside the bar's content box (the menu's panel and the notes float).
  function fits() {
    const box = bar.getBoundingClientRect();
    const right = box.right - parseFloat(getComputedStyle(bar).paddingRight) + 0.5;
    return [...bar.children].every((c) => !c.getClientRects().length || c.getBoundingClientRect().right <= right);
  }

  let fitting = false;
  function fit() {
    if (fitting) return;
    fitting = true;
    let k = 0;
    for (; k <= steps.length; k += 1) {
      apply(k);
      if (fits()) break;
    }
    k = Math.min(k, steps.length);
    // The steps after the links (dots, tighter buttons) may have made room for some of them again.
    const linksOut = steps.slice(0, k).filter((s) => s.kind === 'link').length;
    let back = 0;
    if (steps[k - 1] && steps[k - 1].kind !== 'link') {
      while (back < linksOut) {
        apply(k, back + 1);
        if (!fits()) break;
        back += 1;
      }
      apply(k, back);
    }
    bar.dataset.steps = String(k);
    bar.dataset.linksOut = String(linksOut - back);
    document.documentElement.style.setProperty('--topbar-h', `${bar.getBoundingClientRect().height}px`);
    fitting = false;
  }

  bar.dataset.fit = 'on';
  fit();
  // Sizes change with the window, a pill's word, the e-stop's state, fonts loading: fit again,
  // once per frame at most.
  let queued = false;
  const refit = () => {
    if (queued || fitting) return;
    queued = true;
    requestAnimationFrame(() => { queued = false; fit(); });
  };
  const watch = new ResizeObserver(refit);
  watch.observe(bar);
  for (const child of bar.children) watch.observe(child);
  for (const pill of bar.querySelectorAll('.pill, .estop-button, .estop-all-button')) watch.observe(pill);

  // The menu closes on Escape (focus back on its button), a click elsewhere, or a link followed.
  document.addEventListener('keydown', (e) => {
    if (e.key === 'Escape' && menu.open) { menu.open = false; summary.focus(); }
  });
  document.addEventListener('click', (e) => { if (menu.open && !menu.contains(e.target)) menu.open = false; });
  panel.addEventListener('click', (e) => { if (e.target.closest('a')) menu.open = false; });
}

if (bar && menu) setup();
