// The Settings form: the user's settings put into it and read back from it, each change
// applied at once (the 3D view, switch scanning, speech) and remembered.
import { canSpeak, speak } from "./announce.js";
import { $ } from "./dom.js";
import { setScanMode } from "./scanning.js";
import { saveSettings, settings, switchUser, user } from "./settings.js";
import { shared } from "./shared.js";
import { keyName, wireKeyButtons } from "./switch-keys.js";
import { showView } from "./view-frame.js";

// Put the settings into the form, and apply their side effects.
export function showSettings() {
  $("user").value = user;
  for (const el of document.querySelectorAll("[data-setting]")) {
    const v = settings[el.dataset.setting];
    if (el.type === "checkbox") el.checked = Boolean(v);
    else el.value = String(v);
  }
  for (const k of ["key1", "key2"]) $(k).textContent = `Switch ${k.slice(-1)} key: ${keyName(settings[k])}`;
  showView(settings.showView);
  setScanMode(settings.scanMode);
}

function readSetting(el) {
  const k = el.dataset.setting;
  if (el.type === "checkbox") settings[k] = el.checked;
  else if (el.type === "number") {
    const v = parseFloat(el.value);
    // Out of range or not a number: keep the old value and show it again.
    if (Number.isFinite(v)) settings[k] = Math.min(+el.max, Math.max(+el.min, v));
    el.value = String(settings[k]);
  } else settings[k] = el.value;
  saveSettings();
  if (k === "showView" || k === "viewDetail") showView(settings.showView);
  if (k === "scanMode") setScanMode(settings.scanMode);
  if (k === "speech" && settings.speech) speak("Speech on.", true);
}

export function wireSettingsForm() {
  for (const el of document.querySelectorAll("[data-setting]")) {
    el.addEventListener("change", () => readSetting(el));
  }
  $("user").addEventListener("change", () => {
    switchUser($("user").value.trim().slice(0, 40) || "operator");
    showSettings();
    shared.token = null;  // the lease carries the user's name: take it again on the next command
  });
  wireKeyButtons();
  if (!canSpeak) {
    $("speech").disabled = true;
    $("speech-note").hidden = false;
  }
}
