// The robot selector in the top bar: the server rendered every option's URL (this page for that
// robot, query kept), so choosing one only navigates there.
const select = document.getElementById('robot-select');

// Keys that open the list or move focus on; any other key pressed on the closed selector would
// pick a robot by itself (arrows step, letters jump: "d" is the drone) — and those are the keys
// that drive. So they leave the selector instead and go to the Drive card from the next press.
const CHOOSING_KEYS = new Set(['Tab', 'Enter', ' ', 'Escape']);

if (select) {
  select.addEventListener('change', () => {
    const option = select.selectedOptions[0];
    if (option && option.dataset.robot !== select.dataset.current) window.location.assign(option.value);
  });
  select.addEventListener('keydown', (e) => {
    if (CHOOSING_KEYS.has(e.key) || e.altKey || e.metaKey) return;
    e.preventDefault();
    select.blur();
  });
  // Back from the next robot's page, the browser may restore the form state: show the page's robot.
  window.addEventListener('pageshow', () => {
    for (const option of select.options) option.selected = option.dataset.robot === select.dataset.current;
  });
}
