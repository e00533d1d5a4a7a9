// "Transfer from…" (SPEC §8, issue #23): another scene's placements carried onto this scene's
// character by the server (POST /scenes/{id}/transfer): joints matched across naming conventions,
// then by hierarchy and shape; anchors re-expressed relative to the driver bone and re-projected;
// UV placements made surface placements first. Choosing a scene shows the preview (?apply=false):
// which joint each source joint maps to, what comes over, what cannot and why. "Transfer" applies
// it: one edit, one revision, one undo step.

import { store } from "./store.js";
import { SCENES_PATH, transferPath } from "./scene_resource.js";
import { edit } from "./edits.js";
import { notify } from "./notice.js";

const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

export async function openTransferDialog(api) {
  const dlg = document.getElementById("transferDialog");
  let scenes, models;
  try {
    [scenes, models] = await Promise.all([api.get(SCENES_PATH).then((a) => a.scenes.filter((s) => s.id !== store.sceneId && s.placements > 0)),
                                          api.get("/models").then((a) => a.models).catch(() => [])]);
  } catch (e) { return notify(e.message, "error"); }
  const names = new Map(models.map((m) => [m.id, m.name || m.id]));
  const named = (s) => `${names.get(s.model) || s.model.replace(/^builtin:/, "")} · ${s.placements} placement${s.placements === 1 ? "" : "s"}`;
  dlg.innerHTML = `<h2>Transfer placements onto ${escapeHtml(store.model ? store.model.name || store.model.id : "this character")}</h2>
    ${scenes.length ? `<label>From <select id="transferSource" aria-label="scene to transfer from">${scenes.map((s) => `<option value="${escapeHtml(s.id)}" title="scene ${escapeHtml(s.id)}">${escapeHtml(named(s))}</option>`).join("")}</select></label>`
                    : "<p>There is no other scene with placements.</p>"}
    <div id="transferResult" class="transfer" role="status"></div>
    <form method="dialog"><button type="button" id="transferGo" disabled>Transfer</button> <button>Close</button></form>`;
  const source = dlg.querySelector("#transferSource"), go = dlg.querySelector("#transferGo"), result = dlg.querySelector("#transferResult");
  let shown = null; // the preview on screen: {from, answer}
  const show = async () => {
    const from = source.value;
    go.disabled = true;
    result.textContent = "Matching the joints…";
    try {
      const answer = await api.send("POST", transferPath(store.sceneId, { apply: false }), { from });
      if (source.value !== from) return; // another scene was chosen meanwhile
      shown = { from, answer };
      result.innerHTML = describe(answer);
      go.disabled = !answer.transferred.length;
      go.textContent = `Transfer ${answer.transferred.length}`;
    } catch (e) { result.textContent = `Transfer: ${e.message}`; }
  };
  if (source) { source.onchange = show; show(); }
  go.onclick = async () => {
    if (!shown) return;
    const n = shown.answer.transferred.length;
    go.disabled = true;
    const answer = await edit("POST", "/transfer", { from: shown.from }, { what: `transfer ${n} placement${n === 1 ? "" : "s"}` });
    if (!answer) { go.disabled = false; return; }
    result.innerHTML = `<p class="done">Transferred ${answer.transferred.length} in one revision (r${answer.revision}).</p>` + describe(answer, false);
  };
  dlg.showModal();
}

/// The transfer answer in words: the joint map, what comes over (as what, driven by what) and
/// what does not (with the server's reason).
function describe(a, preview = true) {
  const joints = Object.entries(a.joints || {});
  const rows = a.transferred.map((t) => `<li><b>${escapeHtml(t.from)}</b> → ${escapeHtml(t.placement.label || t.placement.id)} <span class="dim">(${escapeHtml(t.placement.joint)})</span></li>`).join("");
  const lost = a.unmapped.map((u) => `<li><b>${escapeHtml(typeof u.placement === "string" ? u.placement : (u.placement && (u.placement.label || u.placement.id)) || "?")}</b> <span class="dim">${escapeHtml(u.field || "")}</span> — ${escapeHtml(u.reason)}</li>`).join("");
  return `${preview ? `<p>${a.transferred.length} of ${a.transferred.length + a.unmapped.length} placements come over.</p>` : ""}
    ${joints.length ? `<details${preview ? " open" : ""}><summary>Joints (${joints.length})</summary><ul class="jointmap">${joints.map(([s, t]) => `<li>${escapeHtml(s)} → ${escapeHtml(t)}</li>`).join("")}</ul></details>` : ""}
    ${rows ? `<details${preview ? "" : " open"}><summary>Placements coming over (${a.transferred.length})</summary><ul id="transferList">${rows}</ul></details>` : ""}
    ${lost ? `<p>Not transferred (${a.unmapped.length}):</p><ul id="transferUnmapped">${lost}</ul>` : `<p id="transferUnmapped" class="dim">Nothing left behind.</p>`}`;
}
