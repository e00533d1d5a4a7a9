// Library panel: thumbnails of the built-in and uploaded patterns with their kind; the current
// pattern is what 1–9, the place tool and "Place" use. Dropping an image file (on the panel or
// anywhere in the window) uploads it as a pattern; a file that is not an image is refused here
// with a notice and nothing is sent. The list is one tab stop (roving focus): ←/→/↑/↓, Home and
// End move to a pattern and choose it.

import { store, on, set, emit, Topic } from "../store.js";
import { notify } from "../notice.js";
import { patternImagePath } from "../images.js";

let api, list, currentId = null;

export const currentPattern = () => store.patterns.find((p) => p.id === currentId) || store.patterns[0] || null;
export function choosePattern(id) {
  const hadFocus = list && list.contains(document.activeElement);
  currentId = id;
  render();
  emit(Topic.CURRENT_PATTERN);
  if (hadFocus) list.querySelector('button[tabindex="0"]')?.focus();
}

export function initLibrary(section, theApi) {
  api = theApi;
  section.innerHTML = `
    <h2>Library <span class="grow"></span>
      <button type="button" id="uploadPattern" class="mini" title="Upload a pattern image">Upload…</button></h2>
    <div class="library" id="libraryList" role="listbox" aria-label="patterns" data-roving></div>
    <div class="dropzone" id="patternDrop">Drop a PNG/EXR here to add a pattern</div>
    <input type="file" id="patternFile" accept="image/*,.exr" hidden>`;
  list = section.querySelector("#libraryList");
  const file = section.querySelector("#patternFile");
  section.querySelector("#uploadPattern").onclick = () => file.click();
  file.onchange = () => { if (file.files[0]) uploadPattern(file.files[0]); file.value = ""; };
  const drop = section.querySelector("#patternDrop");
  for (const el of [drop, section]) {
    el.addEventListener("dragover", (e) => { e.preventDefault(); drop.classList.add("over"); });
    el.addEventListener("dragleave", () => drop.classList.remove("over"));
    el.addEventListener("drop", (e) => {
      e.preventDefault();
      e.stopPropagation();
      drop.classList.remove("over");
      const f = e.dataTransfer.files[0];
      if (f) uploadPattern(f);
    });
  }
  list.addEventListener("keydown", onListKey);
  on(Topic.PATTERNS, render);
}

/// Arrow keys, Home and End inside the list: the focus and the current pattern move together.
function onListKey(e) {
  const items = [...list.querySelectorAll("button[data-pattern]")];
  const i = items.indexOf(document.activeElement);
  if (i < 0 || e.altKey || e.ctrlKey || e.metaKey) return;
  const columns = Math.max(1, Math.round(list.clientWidth / Math.max(1, items[0].offsetWidth)));
  const step = { ArrowRight: 1, ArrowLeft: -1, ArrowDown: columns, ArrowUp: -columns }[e.key];
  let j = step === undefined ? { Home: 0, End: items.length - 1 }[e.key] : i + step;
  if (j === undefined) return;
  e.preventDefault();
  e.stopPropagation(); // arrows here do not nudge the selected placement
  j = Math.min(items.length - 1, Math.max(0, j));
  choosePattern(items[j].dataset.pattern);
  list.querySelector(`button[data-pattern="${CSS.escape(items[j].dataset.pattern)}"]`).focus();
}

const looksLikeImage = (f) => /^image\//.test(f.type) || /\.(png|exr|jpe?g|tiff?)$/i.test(f.name);

/// Uploads an image file as a pattern (the file's name without extension is its name).
export async function uploadPattern(f) {
  if (!looksLikeImage(f)) {
    notify(`"${f.name}" is not an image: patterns are PNG, EXR, JPEG or TIFF height images. Nothing was uploaded.`, "error");
    return null;
  }
  try {
    const name = f.name.replace(/\.[^.]*$/, "").replace(/[^A-Za-z0-9_.-]/g, "_").slice(0, 60) || "pattern";
    const answer = await api.json("POST", `/patterns?name=${encodeURIComponent(name)}`,
                                  { body: f, headers: { "Content-Type": f.type || "application/octet-stream" } });
    const all = await api.get("/patterns");
    set({ patterns: all.patterns });
    choosePattern(answer.id);
    notify(`Pattern "${answer.name || answer.id}" uploaded.`, "info");
    return answer;
  } catch (e) {
    notify(`Upload of "${f.name}" refused: ${e.message}`, "error");
    return null;
  }
}

function render() {
  list.innerHTML = "";
  store.patterns.forEach((p, i) => {
    const b = document.createElement("button");
    b.type = "button";
    b.setAttribute("role", "option");
    b.dataset.pattern = p.id;
    b.className = p.id === (currentPattern() || {}).id ? "current" : "";
    b.setAttribute("aria-selected", String(b.className === "current"));
    b.tabIndex = b.className === "current" ? 0 : -1;
    b.title = `${p.name} — ${p.kind || "pattern"}${p.description ? ": " + p.description : ""}${i < 9 ? ` (key ${i + 1})` : ""}`;
    b.innerHTML = `<img alt="" src="/api/v1${patternImagePath(p.id)}?size=64" loading="lazy">
      <span>${i < 9 ? `<span class="key">${i + 1}</span> ` : ""}${escapeHtml(p.name || p.id)}</span>
      <span class="kind">${escapeHtml(p.kind || (p.builtin ? "built-in" : "uploaded"))}</span>`;
    b.onclick = () => choosePattern(p.id);
    list.append(b);
  });
}

const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
export { escapeHtml };
