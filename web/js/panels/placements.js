// Placements panel: one row per placement — pattern thumbnail, label (or id), lint badge, enabled
// toggle (H), solo (S) — in document order; drag a row to reorder (PUT of the document with the
// new order); click selects in both views (Shift, Ctrl or Cmd adds). The list is one tab stop (roving focus, on
// the selected row): ↑/↓, Home and End move to a row and select it, Alt+↑/↓ moves the row in the
// document; H and S toggle the focused selection as everywhere.

import { store, on, set, whenIdle, Topic } from "../store.js";
import { patternImagePath } from "../images.js";
import { patchPlacement, putOrder } from "../edits.js";
import { escapeHtml } from "./library.js";
import { rowForListKey } from "../list_keys.js";
import { addsToSelection } from "../selection.js";

let list, count, empty;

export function initPlacements(section) {
  section.innerHTML = `<h2>Placements <span class="badge" id="placementCount">0</span></h2>
    <ul class="list" id="placementList" aria-label="placements" data-roving></ul>
    <p class="empty" id="placementsEmpty" hidden>No placements yet. Choose a pattern in the library, then
      press <kbd>1</kbd>–<kbd>9</kbd> over the texture view, or turn on the place tool (<kbd>P</kbd>) and
      click the model in the 3D view.</p>`;
  list = section.querySelector("#placementList");
  empty = section.querySelector("#placementsEmpty");
  count = section.querySelector("#placementCount");
  list.addEventListener("keydown", onListKey);
  on([Topic.SELECTION, Topic.LINT, Topic.SOLO], render);
  on(Topic.DOC, () => whenIdle("placements", render, 0)); // not on every step of a drag
}

export function toggleEnabled(ids) {
  for (const id of ids) {
    patchPlacement(id, (doc) => {
      const p = doc.placements.find((q) => q.id === id);
      return p ? { enabled: !p.enabled } : null;
    });
  }
}

export function toggleSolo(ids) {
  const solo = new Set(store.solo);
  const all = ids.every((id) => solo.has(id));
  for (const id of ids) all ? solo.delete(id) : solo.add(id);
  set({ solo: [...solo] });
}

/// Moves placement `id` before `beforeId` (end when null): the document with the new order, made
/// from the document as it is when the edit's turn comes (quick moves add up; an edit still on
/// its way is not undone by an older copy of the document).
export async function reorder(id, beforeId) {
  await putOrder((doc) => {
    const ps = [...doc.placements];
    const from = ps.findIndex((p) => p.id === id);
    if (from < 0) return null;
    const [moved] = ps.splice(from, 1);
    const to = beforeId === null ? ps.length : ps.findIndex((p) => p.id === beforeId);
    ps.splice(to < 0 ? ps.length : to, 0, moved);
    return { ...doc, placements: ps };
  });
}

/// Moves placement `id` by `delta` places (Alt+↑/↓), counted in the document as it is when the
/// edit's turn comes: two quick presses move it two places.
async function moveBy(id, delta) {
  await putOrder((doc) => {
    const ps = [...doc.placements];
    const i = ps.findIndex((p) => p.id === id), j = i + delta;
    if (i < 0 || j < 0 || j >= ps.length) return null;
    const [moved] = ps.splice(i, 1);
    ps.splice(j, 0, moved);
    return { ...doc, placements: ps };
  });
}

/// ↑/↓, Home and End on a row: the row before/after (first/last) is selected and focused.
function onListKey(e) {
  const row = rowForListKey(e, list);
  if (!row) return;
  const id = row.dataset.placement;
  set({ selection: [id] });
  list.querySelector(`li[data-placement="${CSS.escape(id)}"] .name`)?.focus();
}

function render() {
  if (!store.doc) return;
  const hadFocus = list.contains(document.activeElement);
  // The row that had the focus keeps it through a re-render (a move's local answer may re-render
  // the list between two Alt+↓ presses: the second must move the same row).
  const focusedId = hadFocus ? document.activeElement.closest("li")?.dataset.placement : null;
  const lintCount = new Map();
  for (const f of store.lint) if (f.placement) lintCount.set(f.placement, (lintCount.get(f.placement) || 0) + 1);
  count.textContent = String(store.doc.placements.length);
  empty.hidden = store.doc.placements.length > 0;
  list.innerHTML = "";
  for (const p of store.doc.placements) {
    const li = document.createElement("li");
    li.dataset.placement = p.id;
    li.draggable = true;
    li.className = (store.selection.includes(p.id) ? "selected " : "") + (p.enabled ? "" : "disabled");
    const lint = lintCount.get(p.id);
    const findings = store.lint.filter((f) => f.placement === p.id).map((f) => f.message).join("\n");
    li.innerHTML = `<img class="thumb" alt="" src="/api/v1${patternImagePath(p.pattern)}?size=64">
      <button type="button" class="name" aria-pressed="${store.selection.includes(p.id)}" title="${p.label ? `${escapeHtml(p.label)} (${escapeHtml(p.id)})` : escapeHtml(p.id)} — ${escapeHtml(p.pattern)} on ${escapeHtml(p.joint)} ${p.axis}${p.projection === "surface" ? ", on the body" : ""}">${escapeHtml(p.label || p.id)}</button>
      ${p.projection === "surface" ? `<span class="surfacetag" role="img" aria-label="on the body" title="On the body: a decal (projection: surface); its outline and anchor are drawn in the texture view">◍</span>` : ""}
      ${lint ? `<span class="lintbadge" title="${escapeHtml(findings)}" aria-label="${lint} lint findings">${lint}</span>` : ""}
      <button type="button" class="mini enabled" aria-pressed="${p.enabled}" aria-label="enabled ${escapeHtml(p.id)}" title="Enabled (H)">${p.enabled ? "◉" : "○"}</button>
      <button type="button" class="mini solo" aria-pressed="${store.solo.includes(p.id)}" aria-label="solo ${escapeHtml(p.id)}" title="Solo in the 3D view (S)">S</button>`;
    li.querySelector(".name").onclick = (e) => {
      const sel = addsToSelection(e) ? (store.selection.includes(p.id) ? store.selection.filter((i) => i !== p.id) : [p.id, ...store.selection]) : [p.id];
      set({ selection: sel });
    };
    li.querySelector(".enabled").onclick = () => toggleEnabled([p.id]);
    li.querySelector(".solo").onclick = () => toggleSolo([p.id]);
    li.addEventListener("dragstart", (e) => { e.dataTransfer.setData("text/x-dermis-placement", p.id); e.dataTransfer.effectAllowed = "move"; });
    li.addEventListener("dragover", (e) => {
      if (![...e.dataTransfer.types].includes("text/x-dermis-placement")) return;
      e.preventDefault();
      li.classList.add("dragover");
    });
    li.addEventListener("dragleave", () => li.classList.remove("dragover"));
    li.addEventListener("drop", (e) => {
      const id = e.dataTransfer.getData("text/x-dermis-placement");
      li.classList.remove("dragover");
      if (!id) return;
      e.preventDefault();
      e.stopPropagation();
      if (id !== p.id) reorder(id, p.id);
    });
    li.addEventListener("keydown", (e) => {
      if (!e.altKey || (e.key !== "ArrowUp" && e.key !== "ArrowDown")) return;
      e.preventDefault();
      e.stopPropagation();
      moveBy(p.id, e.key === "ArrowUp" ? -1 : 1);
    });
    list.append(li);
  }
  // One tab stop: the (first) selected row's name, else the first row's; the toggles are reached
  // by H and S (their buttons stay clickable and labelled).
  const stop = (list.querySelector("li.selected") || list.querySelector("li"));
  for (const b of list.querySelectorAll("button")) b.tabIndex = -1;
  // The row that had the focus keeps it and the tab stop (roving tabindex: Tab out and Shift+Tab
  // back return to it).
  const focusRow = hadFocus ? (focusedId && list.querySelector(`li[data-placement="${CSS.escape(focusedId)}"]`)) || stop : stop;
  if (focusRow) focusRow.querySelector(".name").tabIndex = 0;
  if (hadFocus && focusRow) focusRow.querySelector(".name").focus();
  const sel = list.querySelector("li.selected");
  if (sel) sel.scrollIntoView({ block: "nearest" });
}
