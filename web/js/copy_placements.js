// "Copy placements…": another scene's placements onto this scene's model. Placements whose driver
// joint this model has are added (new ids when taken); those that do not map are listed.

import { store } from "./store.js";
import { edit } from "./edits.js";
import { notify } from "./notice.js";
import { escapeHtml } from "./panels/library.js";

export async function openCopyDialog(api) {
  const dlg = document.getElementById("copyDialog");
  let scenes;
  try { scenes = (await api.get("/scenes")).scenes.filter((s) => s.id !== store.sceneId); } catch (e) { return notify(e.message, "error"); }
  dlg.innerHTML = `<h2>Copy placements onto this scene</h2>
    ${scenes.length ? `<label>From <select id="copySource">${scenes.map((s) => `<option value="${s.id}">${s.id} — ${escapeHtml(s.model)} (${s.placements})</option>`).join("")}</select></label>` : "<p>There is no other scene.</p>"}
    <div id="copyResult" role="status"></div>
    <form method="dialog"><button type="button" id="copyGo"${scenes.length ? "" : " disabled"}>Copy</button> <button>Close</button></form>`;
  dlg.querySelector("#copyGo").onclick = async () => {
    const from = dlg.querySelector("#copySource").value;
    const result = await copyPlacements(api, from);
    if (result) dlg.querySelector("#copyResult").innerHTML = `Copied ${result.copied.length}.` +
      (result.skipped.length ? ` Not mapped (no such joint on this model): <ul>${result.skipped.map((s) => `<li>${escapeHtml(s.id)} — joint ${escapeHtml(s.joint)}</li>`).join("")}</ul>` : "");
  };
  dlg.showModal();
}

/// Copies scene `from`'s placements whose joints this model has: one PUT of the document.
export async function copyPlacements(api, from) {
  let source;
  try { source = (await api.get(`/scenes/${from}`)).scene; } catch (e) { notify(e.message, "error"); return null; }
  const joints = new Set(store.model.joints.map((j) => j.name));
  const taken = new Set(store.doc.placements.map((p) => p.id));
  const copied = [], skipped = [];
  for (const p of source.placements) {
    if (!joints.has(p.joint)) { skipped.push(p); continue; }
    let id = p.id, n = 2;
    while (taken.has(id)) id = `${p.id}_${n++}`;
    taken.add(id);
    copied.push({ ...p, id });
  }
  if (copied.length) {
    const answer = await edit("PUT", "", { ...store.doc, placements: [...store.doc.placements, ...copied] });
    if (!answer) return null;
  }
  return { copied, skipped };
}
