// The robot selector in the top bar: the server rendered every option's URL (this page for that
// robot, query kept), so choosing one only navigates there.
const select = document.getElementById('robot-select');

if (select) {
  select.addEventListener('change', () => {
    const option = select.selectedOptions[0];
    if (option && option.dataset.robot !== select.dataset.current) window.location.assign(option.value);
  });
  // Back from the next robot's page, the browser may restore the form state: show the page's robot.
  window.addEventListener('pageshow', () => {
    for (const option of select.options) option.selected = option.dataset.robot === select.dataset.current;
  });
}
