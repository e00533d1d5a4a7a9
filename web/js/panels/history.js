// History panel: the scene's revisions, newest first, with operation, client and time; click one
// to revert to it (a new revision equal to that one; undoable). Reloads when the revision moves.
// The list is one Tab stop (roving focus, on the current revision's row): ↑/↓, Home and End move
// the focus between revisions without reverting; Enter (or Space) reverts to the focused one.

import { store, on, whenIdle, Topic } from "../store.js";
import { fetchRevisions } from "../scene_resource.js";
import { revert } from "../edits.js";
import { escapeHtml } from "./library.js";
import { notify } from "../notice.js";
import { rowForListKey } from "../list_keys.js";

let api, list, loading = 0;

export function initHistory(section, theApi) {
  api = theApi;
  section.innerHTML = `<h2>History</h2><ul class="list history" id="historyList" aria-label="revisions (arrows move, Enter reverts)" data-roving></ul>`;
  list = section.querySelector("#historyList");
  list.addEventListener("keydown", onListKey);
  on(Topic.REVISION, () => whenIdle("history", load));
  // Another scene: its history at once (not the last scene's until things are quiet).
  on(Topic.SCENE, () => { list.innerHTML = ""; load(); });
}

async function load() {
  if (!store.sceneId) return;
  const mine = ++loading;
  let answer;
  try { answer = await fetchRevisions(api, store.sceneId); } catch (e) { notify(`History: ${e.message}`, "error"); return; }
  if (mine !== loading) return;
  const focused = list.contains(document.activeElement) ? document.activeElement.closest("li")?.dataset.revision : null;
  list.innerHTML = "";
  for (const r of answer.revisions) {
    const li = document.createElement("li");
    li.dataset.revision = String(r.revision);
    if (r.revision === store.revision) li.className = "current";
    const when = new Date(r.time).toLocaleTimeString();
    li.innerHTML = `<button type="button" title="Revert to revision ${r.revision}">r${r.revision} ${escapeHtml(r.op)}
      <div class="when">${escapeHtml(r.client || "—")} · ${escapeHtml(when)}</div></button>`;
    li.querySelector("button").onclick = () => {
      if (r.revision === store.revision) return;
      revert(r.revision);
    };
    list.append(li);
  }
  // One tab stop: the row that had the focus (if still listed), else the current revision's, else
  // the newest; the focus stays in the list across reloads.
  const stop = (focused && list.querySelector(`li[data-revision="${focused}"]`)) || list.querySelector("li.current") || list.querySelector("li");
  for (const b of list.querySelectorAll("button")) b.tabIndex = -1;
  if (stop) {
    stop.querySelector("button").tabIndex = 0;
    if (focused) stop.querySelector("button").focus();
  }
}

/// ↑/↓, Home and End: the focus (and the tab stop) moves to the revision after/before (newest/oldest).
function onListKey(e) {
  const row = rowForListKey(e, list);
  if (!row) return;
  const next = row.querySelector("button");
  for (const b of list.querySelectorAll("button")) b.tabIndex = -1;
  next.tabIndex = 0;
  next.focus();
}
