// The operator's settings, remembered per user in this browser (localStorage), and the
// user's name (which the lease carries too).

const DEFAULTS = {
  step: "0.05", level: "cluster", speed: "0.3", speech: false, showView: true, viewDetail: "auto",
  scanMode: "off", period: 1.0, cycles: 3, accept: 0.1, release: 0.1,  // as the switch adapter
  key1: "Space", key2: "Enter",
};
export let user = safeGet("laserpick.user") || "operator";
export let settings = loadSettings(user);

function safeGet(key) {
  try { return localStorage.getItem(key); } catch { return null; }  // storage may be blocked
}
function loadSettings(name) {
  try { return { ...DEFAULTS, ...JSON.parse(safeGet(`laserpick.settings.${name}`) || "{}") }; }
  catch { return { ...DEFAULTS }; }
}
export function saveSettings() {
  try {
    localStorage.setItem("laserpick.user", user);
    localStorage.setItem(`laserpick.settings.${user}`, JSON.stringify(settings));
  } catch { /* not remembered, but still applied */ }
}

// Another user: their settings from now on, and they are the one remembered.
export function switchUser(name) {
  user = name;
  settings = loadSettings(user);
  saveSettings();
}

// The name the page's lease carries.
export const holderName = () => `${user} (browser page)`.slice(0, 64);
