// "Propose…" (SPEC §8, issue #23): the pattern set the server proposes for this character (POST
// /scenes/{id}/propose: creases, bone ends and bulges with their drivers, θ ranges, scores and
// why) as a list docked over the right-hand panels, so that both views stay in sight. Each row
// says what the proposal is (label, kind, driver joint and θ range, score, why in words) and has
// a checkbox (accept / reject; ticked at first); proposals the scene already has ("existing") say
// so and are never added again. The current row (a click, or ↑ ↓ in the list) is previewed alone
// on the body (proposal_preview.js) and outlined in the 3D view as a ghost (the frame's surface
// brush: a dashed circle at its anchor, as wide as it is); in the texture view every proposal not
// in the scene is a dashed outline in the layout in use (the answer's `outline`; violet when
// ticked, the current one thicker and labelled). "Accept all" and "Accept selected" add
// them in ONE edit — one revision, one undo step: all of them through propose?apply=true, a subset
// by one PUT of the document — and then offer the clip's sweep, where the patterns show.

import { store, on, set, emit, whenIdle, clipByName, Topic } from "./store.js";
import { proposePath } from "./scene_resource.js";
import { edit } from "./edits.js";
import { notify } from "./notice.js";
import { setGhostSource } from "./frame_view.js";
import { setTextureGhosts } from "./texture_view.js";
import { renderProposalPreview } from "./proposal_preview.js";
import { openClipSweep, openSweep } from "./sweep_view.js";

let api = null, panel = null, opener = null;
let proposals = [];        // the propose answer's proposals, as the server orders them
const ticked = new Set();  // ids of the proposals to accept
let current = null;        // id of the proposal previewed and outlined
let accepted = [];         // ids added by the last accept (for the sweep)
let previewAbort = null;
let loading = null;        // the propose request in flight
let lookYaw = null;        // the yaw the current preview shows its proposal from

const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
const idOf = (prop) => prop.placement.id;
const byId = (id) => proposals.find((p) => idOf(p) === id);
const fresh = () => proposals.filter((p) => !p.existing);
export const proposeOpen = () => panel && !panel.hidden;

/// Wires the panel (#proposePanel) and the 3D view's ghost; `button` opens it.
export function initPropose(theApi, button) {
  api = theApi;
  panel = document.getElementById("proposePanel");
  opener = button;
  button.onclick = () => (proposeOpen() ? closePropose() : openPropose());
  setGhostSource(ghost);
  setTextureGhosts(textureGhosts);
  on(Topic.SCENE, () => { if (proposeOpen()) closePropose(false); });
  // Someone (or undo) changed the scene: which proposals it has may have changed too.
  on(Topic.REVISION, () => { if (proposeOpen()) whenIdle("propose", () => load(false), 300); });
  panel.addEventListener("keydown", onKey);
}

/// The current proposal as the 3D view's ghost: [x, y, z, nx, ny, nz, diameter] at its anchor.
function ghost() {
  const prop = proposeOpen() && current && byId(current);
  const p = prop && prop.placement;
  if (!p || p.projection !== "surface" || !p.anchor || !p.size) return null;
  return [...p.anchor.position, ...p.anchor.normal, Math.max(...p.size)];
}

/// Every proposal not in the scene yet as a texture-view ghost: its outline in the layout in use
/// (the propose answer's `outline`), ticked or not, the current one marked.
function textureGhosts() {
  if (!proposeOpen()) return [];
  return fresh().map((p) => ({ outline: p.outline, label: p.placement.label || idOf(p), ticked: ticked.has(idOf(p)), current: idOf(p) === current }));
}

/// Opens the panel and asks the server for proposals.
export async function openPropose() {
  if (!store.sceneId) return;
  panel.hidden = false;
  opener.setAttribute("aria-expanded", "true");
  panel.innerHTML = `<h2>Proposed patterns</h2><p class="hint" role="status">Looking at how ${escapeHtml(modelName())} moves…</p>`;
  accepted = [];
  await load(true);
}

/// Closes the panel (the ghost goes; the focus goes back to the toolbar's button).
export function closePropose(focusBack = true) {
  if (!panel || panel.hidden) return;
  if (previewAbort) previewAbort.abort();
  panel.hidden = true;
  opener.setAttribute("aria-expanded", "false");
  current = null;
  emit(Topic.GHOST);
  if (focusBack) opener.focus();
}

const modelName = () => (store.model && (store.model.name || store.model.id)) || "the character";

/// (Re)reads the proposals; `first` ticks every new one and previews the first row.
async function load(first) {
  const scene = store.sceneId;
  const request = api.send("POST", proposePath(scene), {});
  loading = request;
  let answer;
  try { answer = await request; } catch (e) {
    if (loading === request && proposeOpen()) panel.innerHTML = `<h2>Proposed patterns</h2><p class="hint" role="alert">Propose: ${escapeHtml(e.message)}</p>`;
    return;
  }
  if (loading !== request || scene !== store.sceneId || !proposeOpen()) return;
  take(answer.proposals || [], first);
}

/// Shows `list`. A proposal is ticked when it is new to the panel, or new again (the scene had it
/// and lost it: an undo); the others keep their ticks.
function take(list, first) {
  const before = new Map(proposals.map((p) => [idOf(p), !!p.existing]));
  proposals = list;
  for (const p of proposals) {
    const id = idOf(p);
    if (p.existing) ticked.delete(id);
    else if (first || !before.has(id) || before.get(id)) ticked.add(id);
  }
  const was = current;
  if (first || !byId(current)) current = proposals.length ? idOf(fresh()[0] || proposals[0]) : null;
  render();
  emit(Topic.GHOST);
  if (first || current !== was) preview();
}

/// The proposal's why in words: "left elbow bends 0–22° (animation0 at 1.27 s) · compresses 9 %".
export function whyLine(prop) {
  const w = prop.why || {}, p = prop.placement;
  const pct = (x) => `${Math.round((x || 0) * 100)} %`;
  const range = `${fmt(p.theta_min)}–${fmt(p.theta_max)}°`;
  const when = w.synthetic || !w.peak_clip ? "a range from the rig, no clip bends it" : `${w.peak_clip} at ${fmt(w.peak_time, 2)} s`;
  const strain = prop.kind === "bone" ? `stretches ${pct(w.stretch)}`
    : prop.kind === "bulge" ? `compresses ${pct(w.compression)}, stretches ${pct(w.stretch)}`
    : `compresses ${pct(w.compression)}`;
  return `${w.role || p.joint} bends ${range} (${when}) · ${strain}`;
}
const fmt = (x, digits = 1) => String(Math.round((x || 0) * 10 ** digits) / 10 ** digits);

/// Renders the panel again, the focus kept where it was (on the list where its control went).
function render() {
  const had = panel.contains(document.activeElement) ? document.activeElement.id || (document.activeElement.closest("#proposalList") ? "proposalList" : "") : null;
  fill();
  if (had === null) return;
  const again = had && panel.querySelector("#" + had);
  (again && !again.disabled && !again.hidden ? again : panel.querySelector("#proposalList")).focus();
}

/// The panel's HTML from the proposals; the preview (canvas, words) is kept as it is.
function fill() {
  const kept = panel.querySelector(".proposepreview");
  const n = fresh().length, chosen = fresh().filter((p) => ticked.has(idOf(p))).length;
  const have = proposals.length - n;
  const clip = sweepClip();
  panel.innerHTML = `
    <h2>Proposed patterns <span class="grow"></span><button type="button" class="mini" id="proposeClose" title="Close (Esc)" aria-label="close the proposals">×</button></h2>
    <p class="hint" id="proposeSummary">${proposals.length ? `${proposals.length} for ${escapeHtml(modelName())}${have ? `, ${have} already in the scene` : ""}. Click a row to see it alone on the body; it is circled in the 3D view.`
      : `No proposals for ${escapeHtml(modelName())}: no joint bends its skin enough.`}</p>
    <div class="proposeactions">
      <button type="button" id="proposeAll"${n ? "" : " disabled"} title="Add every proposal not in the scene: one edit, one undo step">Accept all (${n})</button>
      <button type="button" id="proposeSelected"${chosen ? "" : " disabled"} title="Add the ticked proposals: one edit, one undo step">Accept selected (${chosen})</button>
      <button type="button" id="proposeSweep"${accepted.length ? "" : " hidden"} title="${clip ? `The sweep of the clip ${escapeHtml(clip)}: every pattern over its time` : "The sweep of the first added pattern"}">Sweep${clip ? " the clip" : ""}</button>
    </div>
    <ul class="list proposals" id="proposalList" role="listbox" aria-label="proposed patterns" tabindex="0"${current ? ` aria-activedescendant="prop-${escapeHtml(current)}"` : ""}>
      ${proposals.map(row).join("")}
    </ul>
    <div class="proposepreview"><canvas id="proposePreview" width="392" height="144" aria-label="the current proposal alone on the body: where, at its neutral angle, at its peak"></canvas>
      <div class="line"><span id="proposePreviewText" class="hint" role="status"></span>
        <button type="button" id="proposeLook" class="mini" hidden title="Turn the 3D view to the side the preview shows, where the proposal is circled">Turn 3D there</button></div></div>`;
  if (kept) panel.querySelector(".proposepreview").replaceWith(kept);
  const $ = (id) => panel.querySelector("#" + id);
  $("proposeClose").onclick = () => closePropose();
  $("proposeAll").onclick = () => acceptProposals(fresh().map(idOf));
  $("proposeSelected").onclick = () => acceptProposals(fresh().filter((p) => ticked.has(idOf(p))).map(idOf));
  $("proposeSweep").onclick = sweepAccepted;
  $("proposeLook").onclick = (e) => {
    if (lookYaw !== null) set({ camera: { ...store.camera, yaw: lookYaw } });
    e.target.hidden = true;
    panel.querySelector("#proposalList").focus();
  };
  const list = $("proposalList");
  list.onclick = (e) => {
    const li = e.target.closest("li[data-id]");
    if (!li) return;
    if (e.target.matches("input.accept")) { toggle(li.dataset.id, e.target.checked); return; }
    choose(li.dataset.id);
  };
}

function row(prop) {
  const p = prop.placement, id = idOf(prop), on = ticked.has(id);
  const label = p.label || id;
  return `<li id="prop-${escapeHtml(id)}" data-id="${escapeHtml(id)}" role="option" aria-selected="${id === current}" class="${id === current ? "selected" : ""}${prop.existing ? " existing" : ""}">
    <input type="checkbox" class="accept" tabindex="-1" aria-label="accept ${escapeHtml(label)}"${on ? " checked" : ""}${prop.existing ? " disabled" : ""}>
    <div class="proposal">
      <div class="line"><span class="name">${escapeHtml(label)}</span><span class="kindtag" data-kind="${escapeHtml(prop.kind)}">${escapeHtml(prop.kind)}</span>${prop.existing ? `<span class="surfacetag" title="the scene's placement ${escapeHtml(prop.existing)} is this proposal">in the scene</span>` : ""}<span class="score" title="score: how well the joint explains the skin's strain there">${Math.round(prop.score * 100)}</span></div>
      <div class="why" title="${escapeHtml(whyLine(prop))}">${escapeHtml(whyLine(prop))}</div>
      <div class="driver">${escapeHtml(p.joint)} · θ ${fmt(p.theta_min)}–${fmt(p.theta_max)}°${prop.twin ? ` · twin ${escapeHtml(prop.twin)}` : ""}</div>
    </div></li>`;
}

function toggle(id, yes) {
  const prop = byId(id);
  if (!prop || prop.existing) return;
  if (yes) ticked.add(id); else ticked.delete(id);
  emit(Topic.GHOST); // the texture view's ghost turns grey or violet
  const box = panel.querySelector(`li[data-id="${CSS.escape(id)}"] input.accept`);
  if (box) box.checked = yes;
  const chosen = fresh().filter((p) => ticked.has(idOf(p))).length;
  const b = panel.querySelector("#proposeSelected");
  b.textContent = `Accept selected (${chosen})`;
  b.disabled = !chosen;
}

/// Makes `id` the current row: previewed, outlined in 3D, scrolled into sight.
function choose(id) {
  if (!byId(id)) return;
  current = id;
  for (const li of panel.querySelectorAll("#proposalList li")) {
    const yes = li.dataset.id === id;
    li.classList.toggle("selected", yes);
    li.setAttribute("aria-selected", String(yes));
    if (yes) li.scrollIntoView({ block: "nearest" });
  }
  panel.querySelector("#proposalList").setAttribute("aria-activedescendant", `prop-${id}`);
  emit(Topic.GHOST);
  preview();
}

async function preview() {
  const prop = byId(current), canvas = panel.querySelector("#proposePreview"), text = panel.querySelector("#proposePreviewText");
  if (!prop || !canvas) return;
  if (previewAbort) previewAbort.abort();
  const abort = previewAbort = new AbortController();
  text.textContent = `Rendering ${prop.placement.label || current} alone…`;
  canvas.dataset.proposal = "";
  const look = panel.querySelector("#proposeLook");
  look.hidden = true;
  try {
    const shown = await renderProposalPreview(api, prop, canvas, abort.signal);
    if (abort.signal.aborted) return;
    canvas.dataset.proposal = idOf(prop);
    canvas.dataset.pixels = String(shown.pixels);
    lookYaw = shown.side;
    look.hidden = !shown.pixels || Math.abs(((shown.side - (store.camera.yaw ?? 0)) % 360 + 540) % 360 - 180) < 1;
    text.textContent = shown.pixels ? `${prop.placement.label || current} alone at its neutral and its peak angle.`
      : `${prop.placement.label || current} does not show from the front or from behind at its peak: turn the 3D view and look at its circle.`;
  } catch (e) {
    if (e.name !== "AbortError" && !abort.signal.aborted) text.textContent = `The preview could not be rendered: ${e.message}`;
  }
}

/// Adds proposals `ids` (new ones) in one edit and one undo step.
export async function acceptProposals(ids) {
  const all = fresh(), chosen = all.filter((p) => ids.includes(idOf(p)));
  if (!chosen.length) return null;
  const what = chosen.length === 1 ? `add "${chosen[0].placement.label || idOf(chosen[0])}"` : `add ${chosen.length} proposed patterns`;
  const answer = chosen.length === all.length
    ? await edit("POST", "/propose?apply=true", {}, { what })
    : await edit("PUT", "", (doc) => ({ ...doc, placements: [...doc.placements, ...freeIds(doc, chosen.map((p) => p.placement))] }), { what });
  if (!answer) return null;
  const before = new Set(store.doc.placements.map((p) => p.id));
  accepted = answer.applied || chosen.map(idOf).filter((id) => before.has(id));
  notify(`Added ${accepted.length} pattern${accepted.length === 1 ? "" : "s"} in one revision (r${answer.revision}); Ctrl+Z takes ${accepted.length === 1 ? "it" : "them"} back.`, "info",
         { label: "Sweep", run: sweepAccepted }, "propose");
  if (Array.isArray(answer.proposals) && proposeOpen()) take(answer.proposals, false);
  else if (proposeOpen()) await load(false);
  return answer;
}

/// Placements with ids the document does not have yet (`elbow_crease_l_2` where taken).
function freeIds(doc, placements) {
  const taken = new Set(doc.placements.map((p) => p.id));
  return placements.map((p) => {
    let id = p.id, n = 2;
    while (taken.has(id)) id = `${p.id}_${n++}`;
    taken.add(id);
    return { ...p, id };
  });
}

/// The clip that shows the accepted patterns: the scene's, else the one most of them peak in.
function sweepClip() {
  const own = store.doc && store.doc.pose.animation;
  if (own && clipByName(own)) return own;
  const counts = new Map();
  for (const p of proposals) if (p.why && p.why.peak_clip && !p.why.synthetic) counts.set(p.why.peak_clip, (counts.get(p.why.peak_clip) || 0) + 1);
  const best = [...counts].sort((a, b) => b[1] - a[1])[0];
  return best && clipByName(best[0]) ? best[0] : (store.model && store.model.clips[0] ? store.model.clips[0].name : null);
}

function sweepAccepted() {
  const clip = sweepClip();
  if (clip) return openClipSweep(clip);
  const p = store.doc.placements.find((q) => accepted.includes(q.id));
  if (p) openSweep(p);
}

/// Keys in the panel are its own (the editor's single-letter keys do not act on the selection
/// behind it): ↑ ↓ Home End move the current row, Space ticks it, Esc closes.
function onKey(e) {
  if (e.ctrlKey || e.metaKey || e.altKey) return;
  e.stopPropagation();
  const inList = e.target.closest && e.target.closest("#proposalList");
  const i = proposals.findIndex((p) => idOf(p) === current);
  const go = (j) => { if (proposals.length) choose(idOf(proposals[Math.max(0, Math.min(proposals.length - 1, j))])); };
  if (e.key === "Escape") { e.preventDefault(); closePropose(); }
  else if (!inList) return;
  else if (e.key === "ArrowDown") { e.preventDefault(); go(i + 1); }
  else if (e.key === "ArrowUp") { e.preventDefault(); go(i - 1); }
  else if (e.key === "Home") { e.preventDefault(); go(0); }
  else if (e.key === "End") { e.preventDefault(); go(proposals.length - 1); }
  else if (e.key === " " && current) { e.preventDefault(); toggle(current, !ticked.has(current)); }
}
