// The switches' keys (Settings): how a key is named, and changing one (its button listens
// for the next key pressed; Tab keeps the old one, Esc stops as everywhere).
import { $ } from "./dom.js";
import { saveSettings, settings } from "./settings.js";

let listeningFor = null;  // "key1" or "key2" while a switch key is being changed

export function keyName(code) {
  return code.replace(/^Key/, "").replace(/^Digit/, "").replace(/^Arrow/, "Arrow ");
}
export const isListening = () => Boolean(listeningFor);

export function wireKeyButtons() {
  for (const k of ["key1", "key2"]) {
    $(k).addEventListener("click", () => {
      listeningFor = k;
      $(k).classList.add("listening");
      $(k).textContent = `Press the new key for switch ${k.slice(-1)}… (Tab: keep ${keyName(settings[k])})`;
    });
  }
}
// The key pressed while listening becomes the switch's key (e.code: where the key is).
export function takeKey(code) {
  settings[listeningFor] = code;
  saveSettings();
  endListening();
}
export function endListening() {
  listeningFor = null;
  for (const k of ["key1", "key2"]) {
    $(k).classList.remove("listening");
    $(k).textContent = `Switch ${k.slice(-1)} key: ${keyName(settings[k])}`;
  }
}
