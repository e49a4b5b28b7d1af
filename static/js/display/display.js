// The Display menu (templates/partials/display_menu.html): theme and language.
// Each choice is kept where the next page is rendered from: the cookies (the server reads them and
// renders <html data-theme> and the language in the first byte, so no flash), localStorage (the
// browser's own record), and, signed in, the user's preferences on the robot, which follow them to
// any browser. A new theme applies at once; a new language needs the page rendered again.
import { api } from '../core/api.js';
import { _ } from '../core/i18n.js';
import { applyTheme, rememberChoice } from './choices.js';

const menu = document.getElementById('display-menu');

function setup() {
  const theme = document.getElementById('display-theme');
  const language = document.getElementById('display-language');
  const note = document.getElementById('display-kept');
  const signedIn = menu.dataset.signedIn === 'yes';

  async function save(key, value) {
    rememberChoice(key, value);
    if (!signedIn) return;
    try {
      await api('PUT', '/api/me/preferences', { [key]: value }, { root: true });
    } catch (err) {
      // Still kept by this browser: say so rather than pretend the robot has it.
      note.textContent = _('Kept in this browser only: the robot refused to save it (%(reason)s).', { reason: err.message });
      throw err;
    }
  }

  theme.addEventListener('change', () => {
    applyTheme(theme.value);
    save('theme', theme.value).catch(() => {});
  });
  // A new language renders the page again. Picked with the pointer, at once; with the keyboard,
  // an arrow key changes the value at each press, so the page waits for Enter or for the focus to
  // leave the list (WCAG 3.2.2: no change of page while the user is still choosing).
  let pointer = false;
  let saving = null;
  language.addEventListener('pointerdown', () => { pointer = true; });
  language.addEventListener('keydown', (e) => {
    pointer = false;
    if (e.key === 'Enter' && saving) reload();
  });
  language.addEventListener('blur', () => { if (saving) reload(); });
  async function reload() {
    try { await saving; } catch { /* kept in the cookie: render again all the same */ }
    window.location.reload();
  }
  language.addEventListener('change', () => {
    saving = save('language', language.value);
    if (pointer) reload();
    else note.textContent = _('Press Enter to show the page in this language.');
  });

  // Closes on Escape (focus back on its button) or a click elsewhere, like the page menu.
  const summary = menu.querySelector('summary');
  document.addEventListener('keydown', (e) => {
    if (e.key === 'Escape' && menu.open) { menu.open = false; summary.focus(); }
  });
  document.addEventListener('click', (e) => { if (menu.open && !menu.contains(e.target)) menu.open = false; });
}

if (menu) setup();
