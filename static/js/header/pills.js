// The link-health pills as dots (a phone's bar, header.css squeeze-3) keep their words for screen
// readers, and hover never comes on a touch screen: a tap on the dots shows the words under the bar
// for a few seconds (the Errors dot stays a link to the log). A tap again hides them.
const group = document.querySelector('#topbar .link-health');
const words = document.getElementById('link-words');
const SHOWN_MS = 5000;
let hideTimer = null;

function text() {
  return [...group.querySelectorAll('.pill')]
    .map((pill) => `${pill.querySelector('.pill-name').textContent}: ${pill.querySelector('b').textContent}`)
    .join(' · ');
}

function hide() {
  words.hidden = true;
  clearTimeout(hideTimer);
}

if (group && words) {
  group.addEventListener('click', (e) => {
    if (!group.closest('.topbar').classList.contains('squeeze-3') || e.target.closest('a')) return;
    if (!words.hidden) { hide(); return; }
    words.textContent = text();
    words.hidden = false;
    hideTimer = setTimeout(hide, SHOWN_MS);
  });
}
