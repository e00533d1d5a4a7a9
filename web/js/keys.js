// Keyboard shortcuts of the editor (listed by `?`). They act when focus is not in a text field or
// a select; Tab switches texture/3D inside the views (the paper's switch; Shift+Tab leaves them).

import { store, set, placementById, heightmapSize } from "./store.js";
import { pickUVPath, outlinePath } from "./scene_resource.js";
import * as geo from "./geometry.js";
import { removePlacements, mirrorPlacement, addPlacement, patchPlacement, undo, redo, committingChange } from "./edits.js";
import { nudge, withPending } from "./pending.js";
import { cancelDrag, dragging, viewCentreUV, zoomBy, panBy } from "./texture_view.js";
import { setPlaceTool, placeToolOn, resizeBrush } from "./frame_view.js";
import { cancelDecalDrag } from "./camera3d.js";
import { currentPattern, choosePattern } from "./panels/library.js";
import { toggleEnabled, toggleSolo } from "./panels/placements.js";
import { togglePlay } from "./panels/pose.js";
import { placementFromPattern, applySuggested } from "./placing.js";
import { notify } from "./notice.js";
import { openPropose, closePropose, proposeOpen } from "./propose.js";

export const SHORTCUTS = [
  ["1 – 9", "place the library's n-th pattern at the pointer (texture view)"],
  ["click / Shift+click", "select one / add to the selection (Ctrl or Cmd+click adds too; either view, or the list)"],
  ["N / Shift+N", "select the next / previous placement"],
  ["← ↑ → ↓", "nudge the selection one texel (Shift: 10) in the texture — a placement on the body slides over the body to the texel beside its anchor; with nothing selected, pan the texture view (Shift: further)"],
  ["[  ]", "rotate −5° / +5° (Shift: 15°); with the place tool on, the brush smaller / larger"],
  ["+  −", "scale up / down 5% (a placement on the body: its size in model units)"],
  ["Delete", "remove the selection"],
  ["M", "mirror: add the twin on the other side"],
  ["D", "duplicate"],
  ["H", "hide / show (enabled)"],
  ["S", "solo in the 3D view"],
  ["P", "place tool: click the model in 3D to add a placement there (on the body, the brush wide; ⋯ Place as: in the texture)"],
  ["A", "Propose…: the pattern set the server proposes for this character (↑ ↓ walk it, Space ticks, Esc closes)"],
  ["F", "frame the selection in the 3D view (drag orbits about it; Shift+drag or middle drag pans; the wheel zooms at the pointer)"],
  ["Tab", "switch texture / 3D (in the views)"],
  ["T / V / L", "go to the texture view / the 3D view / the placements list"],
  ["Space", "play / pause the clip"],
  ["Ctrl+Z / Ctrl+Shift+Z", "undo / redo (server reverts)"],
  ["Esc", "cancel a drag; leave the place tool; clear the selection"],
  ["Ctrl+=  Ctrl+−", "zoom the texture view in / out (Cmd on a Mac; focus in the texture view)"],
  ["0  Ctrl+0", "fit the texture view"],
  ["?", "this list"],
];

export function initKeys({ fitTexture }) {
  const dlg = document.getElementById("help");
  dlg.innerHTML = `<h2>Keyboard</h2><table>${SHORTCUTS.map(([k, d]) => `<tr><td><kbd>${k}</kbd></td><td>${d}</td></tr>`).join("")}</table>
    <form method="dialog"><button>Close</button></form>`;
  document.getElementById("helpButton").onclick = () => dlg.showModal();
  document.addEventListener("keydown", (e) => onKey(e, { dlg, fitTexture }));
}

const typing = (el) => el && (el.tagName === "INPUT" && !["range", "checkbox", "button"].includes(el.type) || el.tagName === "TEXTAREA" || el.tagName === "SELECT" || el.isContentEditable);

function onKey(e, { dlg, fitTexture }) {
  if (e.key === "Escape" && (cancelDrag() || cancelDecalDrag())) { e.preventDefault(); return; }
  if (document.querySelector("dialog[open]") || document.getElementById("signin").hidden === false) return; // dialogs keep their keys (Esc closes)
  const mod = e.ctrlKey || e.metaKey;
  if (mod && (e.key === "z" || e.key === "Z")) {
    if (typing(document.activeElement)) return;
    e.preventDefault();
    e.shiftKey ? redo() : undo();
    return;
  }
  if (mod && (e.key === "y" || e.key === "Y")) { e.preventDefault(); redo(); return; }
  // Ctrl/Cmd+= / + / − / 0 zoom and fit the texture view while it has the focus (instead of the
  // browser's page zoom, which they keep everywhere else).
  if (mod && !e.altKey && ["=", "+", "-", "_", "0"].includes(e.key) && inTextureView()) {
    e.preventDefault();
    if (e.key === "0") fitTexture();
    else zoomBy(e.key === "=" || e.key === "+" ? 1.25 : 1 / 1.25);
    return;
  }
  if (mod || e.altKey || typing(document.activeElement)) return;
  // Tab on a view shown alone switches to the other view, as the paper does; a second Tab in a
  // row moves on in the page order, so Tab never traps a keyboard user in the views. With both
  // views shown, both are in the page order and Tab simply follows it.
  const active = document.activeElement;
  const onStage = active && (active.id === "uv" || active.id === "frameStage");
  if (e.key === "Tab" && !e.shiftKey && onStage && store.layoutMode !== "both" && active !== tabSwitchedTo) {
    e.preventDefault();
    switchView();
    tabSwitchedTo = document.activeElement;
    return;
  }
  tabSwitchedTo = null;
  const sel = store.selection.filter((id) => placementById(id));
  const k = e.key;
  let handled = true;
  if (k === "?") dlg.showModal();
  else if (/^[1-9]$/.test(k)) committingChange(() => placeNth(+k - 1));
  else if (k === "Escape" && placeToolOn()) setPlaceTool(false); // Esc leaves the place tool first
  else if (k === "Escape") set({ selection: [] });
  else if (k === "n" || k === "N") selectNext(e.shiftKey ? -1 : 1);
  else if (k.startsWith("Arrow") && sel.length) {
    const step = (e.shiftKey ? 10 : 1) / heightmapSize()[0];
    const d = ARROWS[k].map((c) => c * step);
    const uvSel = sel.filter((id) => geo.inTexture(placementById(id)));
    if (uvSel.length) nudge(uvSel, (q) => ({ center: [geo.round4(q.center[0] + d[0]), geo.round4(q.center[1] + d[1])] }), "move");
    const onBody = sel.filter((id) => !geo.inTexture(placementById(id)));
    if (onBody.length) committingChange(() => (bodyNudges = bodyNudges.then(() => nudgeOnBody(onBody, d))));
  } else if (k.startsWith("Arrow") && inTextureView()) {
    const step = e.shiftKey ? 200 : 40; // css px; nothing is selected: the arrows pan
    panBy(...ARROWS[k].map((c) => c * step));
  } else if ((k === "[" || k === "]" || k === "{" || k === "}") && placeToolOn()) {
    resizeBrush(k === "[" || k === "{" ? 1 / 1.25 : 1.25); // the place tool's brush
  } else if ((k === "[" || k === "]" || k === "{" || k === "}") && sel.length) {
    const step = (e.shiftKey ? 15 : 5) * (k === "[" || k === "{" ? -1 : 1);
    nudge(sel, (q) => ({ rotation: geo.round4(geo.wrapDegrees(q.rotation + step)) }), "rotate");
  } else if ((k === "+" || k === "=" || k === "-" || k === "_") && sel.length) {
    const f = k === "+" || k === "=" ? 1.05 : 1 / 1.05;
    const r6 = (x) => Math.round(x * 1e6) / 1e6; // surface sizes are model units (SPEC §8)
    nudge(sel, (q) => (q.projection === "surface" ? { size: [r6(q.size[0] * f), r6(q.size[1] * f)] }
                                                   : { scale: [geo.round4(q.scale[0] * f), geo.round4(q.scale[1] * f)] }), "scale");
  } else if ((k === "Delete" || k === "Backspace") && sel.length) {
    removePlacements(sel);
    set({ selection: [] });
  } else if ((k === "m" || k === "M") && sel.length) sel.forEach((id) => mirrorPlacement(id));
  else if ((k === "d" || k === "D") && sel.length) committingChange(() => duplicate(sel));
  else if ((k === "h" || k === "H") && sel.length) toggleEnabled(sel);
  else if ((k === "s" || k === "S") && sel.length) toggleSolo(sel);
  else if (k === "p" || k === "P") setPlaceTool(!placeToolOn());
  else if ((k === "a" || k === "A") && proposeOpen()) closePropose();
  else if (k === "a" || k === "A") openPropose().then(() => document.getElementById("proposalList")?.focus());
  else if (k === "t" || k === "T") focusView("texture");
  else if (k === "v" || k === "V") focusView("3d");
  else if (k === "l" || k === "L") document.querySelector('#placementList button[tabindex="0"]')?.focus();
  else if (k === " " && !(document.activeElement && document.activeElement.tagName === "BUTTON")) togglePlay();
  else if (k === "0") fitTexture();
  else handled = false;
  if (handled) e.preventDefault();
}

/// The view a Tab just switched to: the next Tab there moves on instead of switching back.
let tabSwitchedTo = null;

/// Unit steps of the arrow keys (x right, y down).
const ARROWS = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };

const inTextureView = () => !!(document.activeElement && document.activeElement.closest && document.activeElement.closest("#textureView"));


/// Switches the single view between texture and 3D; side by side, moves focus to the other view.
export function switchView() {
  const ws = document.querySelector(".workspace");
  const layout = store.layoutMode;
  if (layout === "both") {
    const inTexture = document.activeElement && document.activeElement.closest("#textureView");
    (inTexture ? document.getElementById("frameStage") : document.getElementById("uv")).focus();
    return;
  }
  const next = layout === "texture" ? "3d" : "texture";
  set({ layoutMode: next });
  ws.dataset.layout = next;
  (next === "texture" ? document.getElementById("uv") : document.getElementById("frameStage")).focus();
}

/// Focuses the texture view ("texture") or the 3D view ("3d"), showing it if the layout hides it.
function focusView(which) {
  if (store.layoutMode !== "both" && store.layoutMode !== which) {
    set({ layoutMode: which });
    document.querySelector(".workspace").dataset.layout = which;
  }
  document.getElementById(which === "texture" ? "uv" : "frameStage").focus();
}

function selectNext(dir) {
  const ps = store.doc ? store.doc.placements : [];
  if (!ps.length) return;
  const i = ps.findIndex((p) => p.id === store.selection[0]);
  const j = i < 0 ? (dir > 0 ? 0 : ps.length - 1) : (i + dir + ps.length) % ps.length;
  set({ selection: [ps[j].id] });
}

/// Places the library's n-th pattern at the pointer in the texture view (or the view's centre).
async function placeNth(n) {
  const pattern = store.patterns[n];
  if (!pattern) return notify(`The library has no pattern ${n + 1}.`, "warn");
  if (!store.model || !store.model.has_uvs) return notify("This model has no UVs: patterns cannot be placed on it.", "error");
  choosePattern(pattern.id);
  const uv = store.cursorUV && store.cursorUV.every((x) => x >= 0 && x <= 1) ? store.cursorUV : viewCentreUV();
  const body = placementFromPattern(pattern, uv);
  try {
    const q = await api.get(pickUVPath(store.sceneId, uv));
    if (q.hit && q.suggested) applySuggested(body, q.suggested, pattern);
  } catch { /* no surface there (off the charts): the pattern's defaults stay */ }
  const answer = await addPlacement(body);
  if (answer) set({ selection: [answer.scene.placements[answer.scene.placements.length - 1].id] });
}

let api = null;
export function setKeysApi(theApi) { api = theApi; }

async function duplicate(ids) {
  const added = [];
  for (const id of ids) {
    const p = withPending(placementById(id)); // as shown: a key burst's change is in the copy too
    if (!p) continue;
    const { id: _omit, ...copy } = p;
    if (geo.inTexture(p)) copy.center = [geo.round4(p.center[0] + p.scale[0] * 0.25), geo.round4(p.center[1] + p.scale[1] * 0.25)];
    else { // on the body: a quarter of its width along its tangent (within its depth of the surface)
      const f = geo.surfaceFrame(p);
      if (f) copy.anchor = { ...p.anchor, position: p.anchor.position.map((x, i) => Math.round((x + f.t[i] * p.size[0] * 0.25) * 1e6) / 1e6) };
    }
    const answer = await addPlacement(copy);
    if (answer) added.push(answer.scene.placements[answer.scene.placements.length - 1].id);
  }
  if (added.length) set({ selection: added });
}

export { currentPattern };

// Arrow nudges on the body run one after another: each reads the anchor the one before left, so
// quick presses add up (at the same time they would all start from the same stored anchor).
let bodyNudges = Promise.resolve();

/// Slides placements on the body (SPEC §8) by `d` in the texture: each anchor goes to the body point
/// at the texel beside its own (GET outline's anchor_uv, then pick by UV), its tangent kept; one
/// edit each. A step off the charts leaves the placement where it is.
async function nudgeOnBody(ids, d) {
  for (const id of ids) {
    const p = placementById(id);
    try {
      const o = await api.get(outlinePath(store.sceneId, id));
      if (!o.anchor_uv) continue;
      const uv = [o.anchor_uv[0] + d[0], o.anchor_uv[1] + d[1]];
      if (!uv.every((x) => x >= 0 && x <= 1)) continue;
      const q = await api.get(pickUVPath(store.sceneId, uv));
      if (!q.hit || !q.anchor) continue;
      await patchPlacement(id, { anchor: geo.anchorNear(p, q.anchor) }, { what: `move "${p.label || p.id}"` });
    } catch (err) { notify(`Move: ${err.message}`, "error"); }
  }
}

