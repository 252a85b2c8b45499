// What the page says to the operator besides the status line: speech (optional, off by
// default) and the assertive alerts (what failed or was refused).
import { $ } from "./dom.js";
import { settings } from "./settings.js";

// --- speech -------------------------------------------------------------------------------

export const canSpeak = "speechSynthesis" in window && typeof SpeechSynthesisUtterance === "function";
export function speak(text, interrupt) {
  if (!settings.speech || !canSpeak || !text) return;
  if (interrupt) speechSynthesis.cancel();  // the newest news, not a backlog
  speechSynthesis.speak(new SpeechSynthesisUtterance(text));
}

// --- alerts -------------------------------------------------------------------------------

let lastAlert = { text: "", at: 0, timer: null };
export function alertText(text) {
  // The same alert again within 2 s (a held key's refusals) is said once.
  if (text === lastAlert.text && performance.now() - lastAlert.at < 2000) return;
  lastAlert = { text, at: performance.now(), timer: lastAlert.timer };
  // Empty the region first, so that the same text later is announced again.
  clearAlert();
  lastAlert.timer = setTimeout(() => { $("alert").textContent = text; }, 30);
  speak(text, true);
}
export function clearAlert() {
  clearTimeout(lastAlert.timer);
  $("alert").textContent = "";
}
