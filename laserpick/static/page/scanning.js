// Switch scanning: one or two switches, as keys (their timings are Settings, in s).
//
// Groups first, then the item within the group. One switch (auto): the highlight moves by
// itself every scan period; the switch selects. Two switches (step): switch 1 moves it,
// switch 2 selects. After an item acts, the highlight stays on it for a whole period, so a
// second press repeats it (nudging the laser is many presses). Unavailable items and groups
// with nothing available are skipped. The highlight is steady (no blinking) and announced.
import { speak } from "./announce.js";
import { $ } from "./dom.js";
import { isDriving, setDrive } from "./drive.js";
import { settings } from "./settings.js";
import { keyName } from "./switch-keys.js";

const scan = {
  on: false, level: "top", group: null, el: null, cycles: 0, timer: null,
  down: false, ignored: false, acceptTimer: null, lastRelease: -Infinity, driveFrom: 0,
};
const TOP = () => ["stop", "reset-stop", "g-laser", "g-grasps", "cancel", "g-drive", "g-mode"].map($);

function usable(el) {
  return el && !el.hidden && el.getClientRects().length > 0 && !el.disabled
    && el.getAttribute("aria-disabled") !== "true" && !el.hasAttribute("data-noscan");
}
const groupItems = (g) => [...g.querySelectorAll("button, select")].filter(usable);
// A group is worth entering while it can act: a page setting (a step size) or its Back
// item alone does not count.
const hasActions = (g) => groupItems(g).some((el) => !el.matches(".scan-back, [data-setting]"));
const isGroup = (el) => el.dataset.scan === "group";
const topEntries = () => TOP().filter((el) => (isGroup(el) ? hasActions(el) : usable(el)));
const entries = () => (scan.level === "top" ? topEntries() : groupItems(scan.group));

// A control's name as said and shown: a group's legend, a select's label and choice, a
// button's text without its decorations.
export function nameOf(el) {
  if (isGroup(el)) return `${el.querySelector("legend").textContent} group`;
  if (el.tagName === "SELECT") {
    const label = el.labels[0] ? el.labels[0].firstChild.textContent.trim() : "";
    return `${label}: ${el.selectedOptions[0].textContent}`;
  }
  const hidden = [...el.querySelectorAll("[aria-hidden='true']")].map((n) => n.textContent);
  return hidden.reduce((t, h) => t.replace(h, ""), el.textContent).trim();
}

function highlight(el) {
  if (scan.el) scan.el.classList.remove("scan-hl");
  scan.el = el;
  if (!el) return;
  el.classList.add("scan-hl");
  el.scrollIntoView({ block: "nearest" });
  const text = nameOf(el);
  $("scan-status").textContent = `Scanning: ${text}`;
  speak(text, true);
}

function schedule() {
  clearTimeout(scan.timer);
  if (settings.scanMode === "auto" && scan.on && !scan.down) {
    scan.timer = setTimeout(() => { advance(); schedule(); }, settings.period * 1000);
  }
}

function startScan() {
  scan.on = true;
  scan.level = "top";
  scan.group = null;
  scan.cycles = 0;
  highlight(topEntries()[0]);
  schedule();
}
function pauseScan() {
  scan.on = false;
  clearTimeout(scan.timer);
  highlight(null);
  $("scan-status").textContent = "Scanning paused: press switch 1 to start again.";
}

function advance() {
  const list = entries();
  if (scan.level === "group" && !hasActions(scan.group)) { exitGroup(); return; }  // nothing left
  if (!list.length) { pauseScan(); return; }
  let i = list.indexOf(scan.el) + 1;
  if (i >= list.length) {
    i = 0;
    scan.cycles += 1;
    if (settings.scanMode === "auto" && settings.cycles > 0 && scan.cycles >= settings.cycles) {
      if (scan.level === "group") exitGroup(); else pauseScan();
      return;
    }
  }
  highlight(list[i]);
}

function enterGroup(g) {
  scan.level = "group";
  scan.group = g;
  scan.cycles = 0;
  highlight(groupItems(g)[0]);
}
export function exitGroup() {
  const g = scan.group;
  scan.level = "top";
  scan.group = null;
  scan.cycles = 0;
  highlight(hasActions(g) ? g : topEntries()[0]);
}

// Select the highlighted entry: enter a group, or act and stay on the item.
function select(el) {
  if (!el) return;
  if (isGroup(el)) enterGroup(el);
  else if (el.classList.contains("scan-back")) exitGroup();
  else {
    activate(el);
    scan.cycles = 0;
    highlight(el);
  }
}
function activate(el) {
  if (el.tagName === "SELECT") {  // a select steps to its next option
    el.selectedIndex = (el.selectedIndex + 1) % el.options.length;
    el.dispatchEvent(new Event("change", { bubbles: true }));
  } else if (el.dataset.drive && scan.down) {
    // A drive item is a dead-man: it drives while the switch stays held (a short press:
    // one 0.5 s step).
    scan.driveFrom = performance.now();
    setDrive("switch", el.dataset.drive.split(",").map(Number));
  } else {
    el.click();
  }
}

export function switchDown(sw) {
  const now = performance.now();
  // Release time: a press this soon after the last release is a tremor, not a choice.
  if (now - scan.lastRelease < settings.release * 1000) { scan.ignored = true; return; }
  scan.down = true;
  scan.ignored = false;
  clearTimeout(scan.timer);  // the highlight holds still while the switch is down
  const target = scan.el;    // what was highlighted when the press began
  const accept = () => { scan.acceptTimer = null; onSwitch(sw, target); };
  // Acceptance time: the switch must be held this long to count.
  if (settings.accept > 0) scan.acceptTimer = setTimeout(accept, settings.accept * 1000);
  else accept();
}
export function switchUp() {
  if (scan.ignored) { scan.ignored = false; return; }
  scan.down = false;
  scan.lastRelease = performance.now();
  if (isDriving("switch")) setDrive("switch", null, scan.lastRelease - scan.driveFrom < 300);
  if (scan.acceptTimer) { clearTimeout(scan.acceptTimer); scan.acceptTimer = null; }  // too short
  schedule();
}
function onSwitch(sw, target) {
  if (!scan.on) { startScan(); return; }
  if (settings.scanMode === "auto" || sw === 2) select(target && target.isConnected ? target : scan.el);
  else advance();
}

export function setScanMode(mode) {
  const on = mode !== "off";
  for (const b of document.querySelectorAll(".scan-back")) b.hidden = !on;
  $("scan-status").hidden = !on;
  if (!on) { scan.on = false; clearTimeout(scan.timer); highlight(null); return; }
  const k1 = keyName(settings.key1), k2 = keyName(settings.key2);
  pauseScan();
  $("scan-status").textContent = mode === "auto"
    ? `One-switch scanning: press ${k1} to start.`
    : `Two-switch scanning: ${k1} moves, ${k2} selects. Press ${k1} to start.`;
}
