// History panel: the scene's revisions, newest first, with operation, client and time; click one
// to revert to it (a new revision equal to that one; undoable). Reloads when the revision moves.

import { store, on, whenIdle } from "../store.js";
import { revert } from "../edits.js";
import { escapeHtml } from "./library.js";
import { notify } from "../notice.js";

let api, list, loading = 0;

export function initHistory(section, theApi) {
  api = theApi;
  section.innerHTML = `<h2>History</h2><ul class="list history" id="historyList" aria-label="revisions"></ul>`;
  list = section.querySelector("#historyList");
  on("revision", () => whenIdle("history", load));
}

async function load() {
  if (!store.sceneId) return;
  const mine = ++loading;
  let answer;
  try { answer = await api.get(`/scenes/${store.sceneId}/revisions?limit=40`); } catch (e) { notify(`History: ${e.message}`, "error"); return; }
  if (mine !== loading) return;
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
}
