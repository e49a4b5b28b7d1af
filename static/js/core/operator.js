// The name other browsers see for this operator (who holds control, who engaged the e-stop).
// Kept per browser in localStorage; a random one is made up the first time.

const KEY = 'rover_web.operator';

export function operatorName() {
  try {
    let name = localStorage.getItem(KEY);
    if (!name) {
      name = `browser-${Math.random().toString(36).slice(2, 6)}`;
      localStorage.setItem(KEY, name);
    }
    return name;
  } catch {
    return 'browser';
  }
}

export function setOperatorName(name) {
  const clean = String(name).replace(/\s+/g, ' ').trim().slice(0, 40);
  if (!clean) return operatorName();
  try { localStorage.setItem(KEY, clean); } catch { /* private mode: keep it for this page only */ }
  return clean;
}
