// Texture view: the height-map layout in use (the model's UVs over its base-colour texture, or the
// generated layout), the current bump or displacement map as an optional overlay, and every
// placement as its pattern image inside its rotated footprint, with handles on the selection (drag
// inside: move; corners: scale, Shift keeps aspect; the round handle: rotate, Shift snaps to 15°;
// Esc during a drag cancels it). A surface placement (SPEC §8) is drawn as its decal's outline in
// the layout — every piece, across seams (surface_outlines.js) — with a cross at its anchor; a drag
// on it slides it over the body (on release its anchor goes to the body point under the anchor's
// texel moved by the drag: pick by UV); + − [ ] size and turn it as any selection. Wheel zooms about the pointer; dragging empty space (or with the
// middle button) pans. Lint findings are drawn on the footprints they concern, other people's
// selections in their colour. Labels are placed so that they never overlap (the selection's first,
// then the hovered one, then document order; each tries a few spots around its footprint, or
// around a surface placement's anchor); a label
// with no free spot is hidden until its placement is hovered or selected. Keys (keys.js) zoom
// (Ctrl/Cmd+= / −) and pan (arrows with nothing selected) through zoomBy and panBy.
//
// Draws from the store; edits go through edits.js (a Stream per drag: one edit when it ends).

import { store, on, emit, set, placementById, heightmapSize, Topic } from "./store.js";
import { heightmapPath, pickUVPath } from "./scene_resource.js";
import * as geo from "./geometry.js";
import { image, heightOverlay, onImageLoaded, patternImagePath } from "./images.js";
import { Stream, patchPlacement, committingChange } from "./edits.js";
import { withPending, pendingPreview, hold, release } from "./pending.js";
import { trace } from "./trace.js";
import { addsToSelection } from "./selection.js";
import { initSurfaceOutlines, outlineOf, outlineCurrent, hitOutline, strokeOutline } from "./surface_outlines.js";
import { notify } from "./notice.js";

const HANDLE_PX = 7, ROTATE_OFFSET_PX = 26, ZOOM_MIN = 0.2, ZOOM_MAX = 40;

let api, canvas, ctx, stage, overlaySelect, zoomText;
let zoom = 1, ox = 0, oy = 0, fitted = false; // uv → css px: x = ox + u·zoom·S
let drag = null;  // {kind: move|scale|rotate|pan, id, start, orig, value, stream, corner}
const settling = new Map(); // id → {delta, done, moved, scene}: a surface placement let go of after a slide (surfaceOffset)
let hover = null; // id under the pointer
let dirty = false;
let labels = { shown: [], hidden: [] }; // the last draw's label layout (css px in the canvas)
const LABEL_FONT = "11px system-ui, sans-serif", LABEL_H = 14;

const S = () => Math.min(stage.clientWidth, stage.clientHeight) || 512;
/// A footprint's colour (outline and label) by its target: displacement warm, bump cool.
const targetColor = (p) => (p && p.target === "displacement" ? "#ff9a7a" : "#7fd0ff");
const toScreen = (uv) => [ox + uv[0] * zoom * S(), oy + uv[1] * zoom * S()];
const toUV = (x, y) => [(x - ox) / (zoom * S()), (y - oy) / (zoom * S())];
const pxToUV = (px) => px / (zoom * S());

/// The placement as drawn: the document's, with pending changes (a drag's value, a key burst, a
/// gesture's edit on its way) on top.
const shown = withPending;

export function initTextureView(section, theApi) {
  api = theApi;
  initSurfaceOutlines(theApi, () => redraw());
  section.innerHTML = `
    <div class="viewbar">
      <span class="title">Texture</span>
      <label><span class="lbl">Overlay</span> <select id="overlay" aria-label="height-map overlay" title="Height-map overlay">
        <option value="none">none</option><option value="bump">bump map</option><option value="displacement">displacement map</option>
      </select></label>
      <button type="button" id="fitTexture" title="Fit the UV square (0)">Fit</button>
      <span id="zoomText" class="badge">100%</span>
      <span class="hint">1–9 place · drag move · corners scale · ◯ rotate · ? keys</span>
    </div>
    <div class="stage"><canvas id="uv" tabindex="0" aria-label="texture space: placements on the UV layout; arrow keys nudge the selection"></canvas></div>`;
  stage = section.querySelector(".stage");
  canvas = section.querySelector("#uv");
  ctx = canvas.getContext("2d");
  overlaySelect = section.querySelector("#overlay");
  zoomText = section.querySelector("#zoomText");
  overlaySelect.onchange = () => set({ overlay: overlaySelect.value });
  section.querySelector("#fitTexture").onclick = fit;
  new ResizeObserver(() => { if (!fitted) fit(); else redraw(); }).observe(stage);
  canvas.addEventListener("pointerdown", pointerDown);
  canvas.addEventListener("pointermove", pointerMove);
  canvas.addEventListener("pointerup", pointerUp);
  canvas.addEventListener("pointercancel", () => cancelDrag());
  canvas.addEventListener("wheel", wheel, { passive: false });
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  on([Topic.DOC, Topic.SELECTION, Topic.LINT, Topic.PRESENCE, Topic.OVERLAY, Topic.LAYOUT, Topic.MODEL, Topic.REVISION, Topic.SOLO,
      Topic.DRAG, Topic.GHOST], redraw);
  on(Topic.LAYOUT_MODE, () => requestAnimationFrame(fit)); // the stage changed size: fit the UV square again
  onImageLoaded(redraw);
}

/// Fits the UV square into the stage.
export function fit() {
  fitted = true;
  zoom = 0.94;
  const w = stage.clientWidth, h = stage.clientHeight, s = S();
  ox = (w - s * zoom) / 2;
  oy = (h - s * zoom) / 2;
  redraw();
}

export function redraw() {
  if (dirty) return;
  dirty = true;
  requestAnimationFrame(draw);
}

/// What the frame should preview ({id: fields}: a drag, a key burst), or null.
export const dragPreview = pendingPreview;

/// True while a drag runs (Esc cancels it; see cancelDrag).
export const dragging = () => drag !== null && drag.kind !== "pan";

/// Centre of the visible part of the UV square (where keys place patterns when the pointer is away).
export function viewCentreUV() {
  return toUV(stage.clientWidth / 2, stage.clientHeight / 2).map((x) => Math.min(Math.max(x, 0), 1));
}

function draw() {
  dirty = false;
  if (!canvas) return;
  const dpr = window.devicePixelRatio || 1;
  const w = stage.clientWidth, h = stage.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.fillStyle = "#0d1014";
  ctx.fillRect(0, 0, w, h);
  zoomText.textContent = `${Math.round(zoom * 100)}%`;
  if (!store.doc || !store.model) return;
  const s = zoom * S();
  // The UV square, its texture and the overlay.
  ctx.fillStyle = "#1a1f26";
  ctx.fillRect(ox, oy, s, s);
  // Only a model with a base-colour texture is asked for one (no 404 on a clean load), and only
  // where the maps live in the model's own UVs (a generated layout has no texture under it).
  const ownUVs = store.layout && store.layout.layout === "model";
  const tex = ownUVs && store.model.has_texture ? image(`/models/${encodeURIComponent(store.model.id)}/texture?size=1024`) : null;
  if (tex) {
    ctx.globalAlpha = 0.55;
    ctx.drawImage(tex, ox, oy, s, s);
    ctx.globalAlpha = 1;
  }
  if (store.overlay !== "none") {
    const ov = heightOverlay(heightmapPath(store.sceneId, store.overlay, store.overlayRevision || store.revision));
    if (ov) ctx.drawImage(ov, ox, oy, s, s);
  }
  if (store.layout) {
    ctx.strokeStyle = "rgba(140, 160, 185, 0.35)";
    ctx.lineWidth = 1;
    ctx.beginPath();
    const e = store.layout.edges;
    for (let i = 0; i + 3 < e.length; i += 4) {
      ctx.moveTo(ox + e[i] * s, oy + e[i + 1] * s);
      ctx.lineTo(ox + e[i + 2] * s, oy + e[i + 3] * s);
    }
    ctx.stroke();
  } else {
    ctx.fillStyle = "#ffb454";
    ctx.fillText("This model has no UVs: patterns cannot be placed on it.", ox + 10, oy + 20);
  }
  ctx.strokeStyle = "#3a4350";
  ctx.strokeRect(ox, oy, s, s);

  const lintBy = new Map();
  for (const f of store.lint) if (f.placement) lintBy.set(f.placement, [...(lintBy.get(f.placement) || []), f]);
  const soloed = new Set(store.solo);
  // Dimmed: hidden, or another placement soloed. Footprints first, the surface outlines over them.
  const dims = new Map(store.doc.placements.map((p) => [p.id, !p.enabled || (soloed.size > 0 && !soloed.has(p.id))]));
  for (const raw of store.doc.placements.filter(geo.inTexture)) {
    const p = shown(raw);
    drawFootprint(p, { selected: store.selection.includes(p.id), dim: dims.get(p.id), lint: lintBy.get(p.id) || [], hover: hover === p.id });
  }
  for (const p of store.doc.placements) if (!geo.inTexture(p)) drawSurfaceOutline(p, dims.get(p.id));
  drawLabels(dims, w, h);
  drawGhosts();
  // Other people's selections, in their colour.
  for (const [client, who] of store.presence) {
    for (const id of who.selection || []) {
      const p = placementById(id);
      if (!p || !geo.inTexture(p)) continue;
      outline(p, who.color || "#f0f", 3, [6, 4]);
      const [x, y] = toScreen(geo.toUV(p, [0, 1]));
      ctx.fillStyle = who.color || "#f0f";
      ctx.fillText(client, x, y + 12);
    }
  }
  const prim = store.selection.length ? placementById(store.selection[0]) : null;
  if (prim && geo.inTexture(prim)) drawHandles(shown(prim));
}

let ghostsOf = () => [];
/// fn() → [{outline, label, ticked, current}]: footprints not in the scene yet (Propose…'s
/// proposals, their outlines from the propose answer), drawn dashed over the layout.
export function setTextureGhosts(fn) { ghostsOf = fn; }

/// The ghosts: dashed outlines (violet when ticked, grey when not; the current one thicker, with its
/// label at its anchor).
function drawGhosts() {
  for (const g of ghostsOf()) {
    const o = g.outline;
    if (!o || !o.segments) continue;
    ctx.strokeStyle = g.ticked ? "#b48cff" : "#7d8794";
    ctx.lineWidth = g.current ? 2.6 : 1.6;
    ctx.setLineDash([5, 4]);
    ctx.beginPath();
    for (const seg of o.segments) {
      ctx.moveTo(...toScreen([seg[0], seg[1]]));
      ctx.lineTo(...toScreen([seg[2], seg[3]]));
    }
    ctx.stroke();
    ctx.setLineDash([]);
    if (g.current && o.anchor_uv) {
      const [x, y] = toScreen(o.anchor_uv);
      ctx.font = LABEL_FONT;
      ctx.fillStyle = ctx.strokeStyle;
      ctx.fillText(g.label, x + 6, y - 6);
    }
  }
}

/// A surface placement's decal outline (all pieces) and a cross at its anchor (its label is laid
/// out with the others: layoutLabels).
function drawSurfaceOutline(p, dim) {
  const selected = store.selection.includes(p.id), hovered = hover === p.id;
  ctx.globalAlpha = dim ? 0.35 : 1;
  ctx.strokeStyle = selected ? "#ffffff" : hovered ? "#c8e1ff" : targetColor(p);
  ctx.lineWidth = selected || hovered ? 2 : 1.4;
  ctx.setLineDash(p.enabled ? [] : [4, 3]);
  strokeOutline(ctx, p, toScreen, surfaceOffset(p));
  ctx.setLineDash([]);
  const a = anchorOnScreen(p);
  if (a) {
    const [x, y] = a;
    ctx.beginPath();
    ctx.moveTo(x - 4, y); ctx.lineTo(x + 4, y); ctx.moveTo(x, y - 4); ctx.lineTo(x, y + 4);
    ctx.stroke();
  }
  ctx.globalAlpha = 1;
}

/// Surface placement `p`'s anchor on screen (as drawn: with the slide's offset), where its cross
/// is drawn and its label goes; null while its outline is not in.
function anchorOnScreen(p) {
  const o = outlineOf(p);
  if (!o || !o.anchor_uv) return null;
  const off = surfaceOffset(p);
  return toScreen([o.anchor_uv[0] + off[0], o.anchor_uv[1] + off[1]]);
}

/// How far (UV) stored surface placement `p`'s outline is drawn from where it is stored: the drag's
/// offset while it slides; after, until its new outline is in (the pick, the edit and the outline
/// read take three round trips), where it was let go of, so that it does not snap back meanwhile.
function surfaceOffset(p) {
  if (drag && drag.kind === "smove" && drag.id === p.id) return drag.delta;
  const s = settling.get(p.id);
  if (!s) return [0, 0];
  if (s.scene !== store.sceneId) { settling.delete(p.id); return [0, 0]; } // another scene's placement of that id
  // Done: the moved placement's own outline is in, or it has changed since (an undo, another
  // person's edit) and its outline is not where it was let go of.
  if (s.done && (outlineCurrent(p) || JSON.stringify(p) !== s.moved)) { settling.delete(p.id); return [0, 0]; }
  return s.delta;
}

function outline(p, color, width, dash = []) {
  const c = geo.corners(p).map(toScreen);
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.setLineDash(dash);
  ctx.beginPath();
  ctx.moveTo(...c[0]);
  for (let i = 1; i < 4; ++i) ctx.lineTo(...c[i]);
  ctx.closePath();
  ctx.stroke();
  ctx.setLineDash([]);
}

function drawFootprint(p, { selected, dim, lint, hover: hovered }) {
  const s = zoom * S();
  const [cx, cy] = toScreen(p.center);
  const img = image(patternImagePath(p.pattern));
  ctx.save();
  ctx.translate(cx, cy);
  ctx.rotate((p.rotation * Math.PI) / 180);
  const w = p.scale[0] * s, h = p.scale[1] * s;
  if (img) {
    ctx.globalAlpha = dim ? 0.18 : 0.62;
    ctx.drawImage(img, -w / 2, -h / 2, w, h);
    ctx.globalAlpha = 1;
  }
  ctx.restore();
  const color = targetColor(p);
  outline(p, selected ? "#ffffff" : color, selected ? 2 : hovered ? 2 : 1.2, p.enabled ? [] : [4, 3]);
  if (lint.length) {
    const [tx, ty] = toScreen(geo.toUV(p, [1, 0]));
    ctx.fillStyle = "#ffb454";
    ctx.beginPath();
    ctx.moveTo(tx, ty - 16);
    ctx.lineTo(tx + 9, ty - 1);
    ctx.lineTo(tx - 9, ty - 1);
    ctx.closePath();
    ctx.fill();
    ctx.fillStyle = "#111";
    ctx.font = "bold 10px system-ui, sans-serif";
    ctx.fillText(lint.length > 1 ? String(lint.length) : "!", tx - 3, ty - 3);
  }
}

/// Places every placement's label where it overlaps no other label: the selection's first (always
/// shown), then the hovered one (always shown), then document order; each tries above / below its
/// footprint's box (left, then right aligned), inside it, and beside it, preferring spots inside
/// the stage. A surface placement's "footprint" is the cross at its anchor (its label first
/// tries above right of it). A label with no free spot is hidden (hover or select its placement
/// to see it).
function layoutLabels(w, h) {
  const ps = store.doc.placements.map((p) => (geo.inTexture(p) ? shown(p) : p));
  const rank = (p) => { const i = store.selection.indexOf(p.id); return i >= 0 ? i : p.id === hover ? store.selection.length : Infinity; };
  const order = ps.map((p, i) => ({ p, i, r: rank(p) })).sort((a, b) => a.r - b.r || a.i - b.i);
  ctx.font = LABEL_FONT;
  const placed = obstacles(), hidden = [];
  const free = (b) => placed.every((o) => b.x + b.w + 2 <= o.x || o.x + o.w + 2 <= b.x || b.y + b.h + 1 <= o.y || o.y + o.h + 1 <= b.y);
  const inside = (b) => b.x >= 0 && b.y >= 0 && b.x + b.w <= w && b.y + b.h <= h;
  for (const { p, r } of order) {
    const text = p.label || p.id;
    const lw = Math.ceil(ctx.measureText(text).width) + 6, lh = LABEL_H;
    const surface = !geo.inTexture(p);
    let x0, x1, y0, y1;
    if (surface) {
      const a = anchorOnScreen(p);
      if (!a) continue; // its outline is not in yet: nothing drawn for it, no label
      [x0, y0, x1, y1] = [a[0] - 5, a[1] - 5, a[0] + 5, a[1] + 5]; // the cross
    } else {
      const c = geo.corners(p).map(toScreen);
      x0 = Math.min(...c.map((q) => q[0])); x1 = Math.max(...c.map((q) => q[0]));
      y0 = Math.min(...c.map((q) => q[1])); y1 = Math.max(...c.map((q) => q[1]));
    }
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    const m = p.id === store.selection[0] && !surface ? HANDLE_PX / 2 + 2 : 1; // clear of the selection's corner handles
    const around = [[x0, y0 - lh - m], [x0, y1 + m], [x1 - lw, y0 - lh - m], [x1 - lw, y1 + m]];
    const spots = (surface ? [[x1 + 1, y0 - lh + 2], [x1 + 1, y1 - 2], [x0 - lw - 1, y0 - lh + 2], [x0 - lw - 1, y1 - 2], ...around]
                           : [...around, [cx - lw / 2, cy - lh / 2], [x1 + 2, cy - lh / 2], [x0 - lw - 2, cy - lh / 2]])
      .map(([x, y]) => ({ id: p.id, text, x: Math.round(x), y: Math.round(y), w: lw, h: lh }));
    const must = r !== Infinity; // selected or hovered
    // A spot that fits nowhere inside the stage is moved inside it (never cut at the view's edge).
    const clamp = (b) => ({ ...b, x: Math.round(Math.min(Math.max(b.x, 0), Math.max(w - b.w, 0))), y: Math.round(Math.min(Math.max(b.y, 0), Math.max(h - b.h, 0))) });
    const box = spots.find((b) => free(b) && inside(b)) || spots.map(clamp).find(free) || (must ? clamp(spots[0]) : null);
    if (box) placed.push(box);
    else hidden.push(p.id);
  }
  return { shown: placed.filter((b) => !b.obstacle), hidden };
}

/// What labels keep clear of: the selection's handles (and the rotation handle's stem), the lint
/// marks and other people's names (boxes in css px).
function obstacles() {
  const boxes = [];
  const box = (x0, y0, x1, y1) => boxes.push({ obstacle: true, x: Math.min(x0, x1), y: Math.min(y0, y1), w: Math.abs(x1 - x0), h: Math.abs(y1 - y0) });
  const r = HANDLE_PX / 2 + 1;
  const prim = store.selection.length ? placementById(store.selection[0]) : null;
  if (prim && geo.inTexture(prim)) {
    const hp = handlePoints(shown(prim));
    for (const [x, y] of hp.corners) box(x - r, y - r, x + r, y + r);
    box(hp.rotate[0] - r - 1, hp.rotate[1] - r - 1, hp.rotate[0] + r + 1, hp.rotate[1] + r + 1);
    box(hp.top[0] - 1, hp.top[1] - 1, hp.rotate[0] + 1, hp.rotate[1] + 1);
  }
  const linted = new Set(store.lint.map((f) => f.placement).filter(Boolean));
  for (const id of linted) {
    const p = placementById(id);
    if (!p) continue;
    const [tx, ty] = toScreen(geo.toUV(shown(p), [1, 0]));
    box(tx - 9, ty - 16, tx + 9, ty - 1);
  }
  for (const [client, who] of store.presence) {
    for (const id of who.selection || []) {
      const p = placementById(id);
      if (!p) continue;
      const [x, y] = toScreen(geo.toUV(p, [0, 1]));
      box(x, y + 1, x + ctx.measureText(client).width, y + 15);
    }
  }
  return boxes;
}

function drawLabels(dims, w, h) {
  labels = { ...layoutLabels(w, h), selection: store.selection[0] ?? null };
  ctx.font = LABEL_FONT;
  ctx.textBaseline = "middle";
  for (const b of labels.shown) {
    const p = placementById(b.id);
    const color = targetColor(p);
    const selected = store.selection.includes(b.id);
    ctx.fillStyle = selected ? "rgba(36, 56, 77, 0.92)" : "rgba(13, 16, 20, 0.72)";
    ctx.fillRect(b.x, b.y, b.w, b.h);
    ctx.fillStyle = selected ? "#ffffff" : dims.get(b.id) ? "#8d99a8" : color;
    ctx.fillText(b.text, b.x + 3, b.y + b.h / 2 + 0.5);
  }
  ctx.textBaseline = "alphabetic";
}

/// The last drawn label layout, for tests: {shown: [{id, x, y, w, h}] in client px, hidden: [id],
/// selection: the placement selected when it was drawn (null for none)}. It is drawn on the next
/// animation frame after a change, so a test waits for the selection it set.
export function labelLayout() {
  const r = canvas.getBoundingClientRect();
  return { shown: labels.shown.map(({ id, x, y, w, h }) => ({ id, x: r.left + x, y: r.top + y, w, h })), hidden: [...labels.hidden],
           selection: labels.selection ?? null };
}

function handlePoints(p) {
  const c = geo.corners(p).map(toScreen);
  const r = toScreen(geo.rotationHandle(p, pxToUV(ROTATE_OFFSET_PX)));
  const top = toScreen(geo.toUV(p, [0.5, 0]));
  return { corners: c, rotate: r, top };
}

function drawHandles(p) {
  const hp = handlePoints(p);
  ctx.strokeStyle = "#ffffff";
  ctx.lineWidth = 1;
  ctx.beginPath();
  ctx.moveTo(...hp.top);
  ctx.lineTo(...hp.rotate);
  ctx.stroke();
  ctx.fillStyle = "#5fb3ff";
  for (const [x, y] of hp.corners) {
    ctx.fillRect(x - HANDLE_PX / 2, y - HANDLE_PX / 2, HANDLE_PX, HANDLE_PX);
    ctx.strokeRect(x - HANDLE_PX / 2, y - HANDLE_PX / 2, HANDLE_PX, HANDLE_PX);
  }
  ctx.beginPath();
  ctx.arc(hp.rotate[0], hp.rotate[1], HANDLE_PX / 2 + 1, 0, Math.PI * 2);
  ctx.fill();
  ctx.stroke();
}

/// What is under css pixel (x, y): {kind: scale, corner} | {kind: rotate} on the primary
/// selection's handles, {kind: move, id} on a footprint, or null.
function under(x, y) {
  const prim = store.selection.length ? placementById(store.selection[0]) : null;
  if (prim && geo.inTexture(prim)) {
    const hp = handlePoints(shown(prim));
    const near = (pt, r) => Math.hypot(pt[0] - x, pt[1] - y) <= r;
    if (near(hp.rotate, HANDLE_PX)) return { kind: "rotate", id: prim.id };
    for (let k = 0; k < 4; ++k) if (near(hp.corners[k], HANDLE_PX)) return { kind: "scale", id: prim.id, corner: k };
  }
  const p = geo.hit(store.doc.placements.map(shown), toUV(x, y));
  if (p) return { kind: "move", id: p.id };
  const q = hitOutline(store.doc.placements, toUV(x, y), pxToUV(3), surfaceOffset);
  return q ? { kind: "smove", id: q.id } : null;
}

function local(e) {
  const r = canvas.getBoundingClientRect();
  return [e.clientX - r.left, e.clientY - r.top];
}

function capture(e) {
  try { canvas.setPointerCapture(e.pointerId); } catch { /* a synthetic pointer (scripts, tests) */ }
}

function pointerDown(e) {
  if (!store.doc) return;
  canvas.focus();
  const [x, y] = local(e);
  const uv = toUV(x, y);
  if (e.button === 1 || e.button === 2) {
    drag = { kind: "pan", start: [x, y], orig: [ox, oy] };
    capture(e);
    return;
  }
  if (e.button !== 0) return;
  const what = under(x, y);
  if (!what) {
    if (!addsToSelection(e)) set({ selection: [] });
    drag = { kind: "pan", start: [x, y], orig: [ox, oy] };
    canvas.classList.add("grab");
    capture(e);
    return;
  }
  if (what.kind === "move" || what.kind === "smove") {
    if (addsToSelection(e)) {
      const sel = store.selection.includes(what.id) ? store.selection.filter((i) => i !== what.id) : [what.id, ...store.selection];
      set({ selection: sel });
      return;
    }
    // A plain click selects this placement alone, as in every editor.
    if (store.selection.length !== 1 || store.selection[0] !== what.id) set({ selection: [what.id] });
  }
  if (store.pinnedRevision !== null) return; // an old revision is shown: no edits until the person leaves it
  if (what.kind === "smove") {
    drag = { kind: "smove", id: what.id, start: uv, delta: [0, 0] };
    capture(e);
    return;
  }
  const orig = withPending(placementById(what.id));
  const verb = { move: "move", scale: "scale", rotate: "rotate" }[what.kind];
  drag = { ...what, start: uv, orig, value: null,
           stream: new Stream((fields) => patchPlacement(what.id, fields, { undoable: false }),
                              { what: `${verb} "${orig.label || orig.id}"` }) };
  capture(e);
}

function pointerMove(e) {
  const [x, y] = local(e);
  const uv = toUV(x, y);
  set({ cursorUV: uv });
  if (!drag) {
    const what = store.doc ? under(x, y) : null;
    const id = what ? what.id : null;
    canvas.style.cursor = !what ? "crosshair" : what.kind === "move" || what.kind === "smove" ? "move" : what.kind === "rotate" ? "alias" : "nwse-resize";
    if (id !== hover) { hover = id; redraw(); }
    if (what && (what.kind === "move" || what.kind === "smove")) {
      const lint = store.lint.filter((f) => f.placement === what.id).map((f) => f.message);
      canvas.title = [what.id, ...lint].join("\n");
    } else canvas.title = "";
    return;
  }
  if (drag.kind === "pan") {
    ox = drag.orig[0] + x - drag.start[0];
    oy = drag.orig[1] + y - drag.start[1];
    redraw();
    return;
  }
  if (drag.kind === "smove") {
    drag.delta = [uv[0] - drag.start[0], uv[1] - drag.start[1]];
    redraw();
    return;
  }
  const o = drag.orig;
  if (drag.kind === "move") drag.value = geo.moved(o, drag.start, uv);
  else if (drag.kind === "rotate") drag.value = geo.rotated(o, uv, e.shiftKey);
  else drag.value = geo.scaled(o, drag.corner, uv, e.shiftKey);
  if (trace.on) trace.moves.push(performance.now());
  drag.stream.send(drag.value);
  hold(drag.id, drag.value); // shown and previewed until the one edit of the gesture is answered
  redraw();
}

async function pointerUp(e) {
  canvas.classList.remove("grab");
  if (!drag) return;
  const d = drag;
  drag = null;
  if (d.kind === "pan") return;
  if (d.kind === "smove") {
    const s = { delta: d.delta, done: false, scene: store.sceneId };
    settling.set(d.id, s);
    await committingChange(() => slideOnBody(d, s));
    return;
  }
  if (!d.value) { d.stream.done = true; d.stream.end(); return; }
  await d.stream.finish(); // one edit: the gesture's last value
  release(d.id, d.value);
  redraw();
}

/// Cancels a running drag: restores the placement (see Stream.cancel). True when one ran.
export function cancelDrag() {
  if (!drag || drag.kind === "pan") return false;
  if (drag.kind === "smove") { drag = null; redraw(); return true; }
  const d = drag;
  drag = null;
  release(d.id);
  d.stream.cancel().then(redraw);
  redraw();
  return true;
}

/// Ends a drag of surface placement d.id by d.delta UV: its anchor goes to the body point at its
/// anchor's texel moved by the drag (pick by UV), its tangent kept; one edit, one undo step. Off
/// the charts it stays where it was (and says so).
async function slideOnBody(d, settle) {
  const p = placementById(d.id);
  const o = p && outlineOf(p);
  const stays = () => { if (settling.get(d.id) === settle) settling.delete(d.id); redraw(); };
  if (!p || !o || !o.anchor_uv || Math.hypot(...d.delta) < 1e-6) { stays(); return; }
  const uv = [o.anchor_uv[0] + d.delta[0], o.anchor_uv[1] + d.delta[1]];
  let moved = false;
  try {
    const hit = uv.every((x) => x >= 0 && x <= 1) ? await api.get(pickUVPath(store.sceneId, uv)) : { hit: false };
    if (!hit.hit || !hit.anchor) notify(`"${p.label || p.id}" stays: no body under that point of the layout.`, "warn");
    else moved = !!(await patchPlacement(d.id, { anchor: geo.anchorNear(p, hit.anchor) }, { what: `move "${p.label || p.id}"` }));
  } finally {
    if (moved) { settle.moved = JSON.stringify(placementById(d.id)); settle.done = true; redraw(); }
    else stays(); // off the body or refused: back where it is
  }
}

function wheel(e) {
  e.preventDefault();
  zoomAbout(...local(e), Math.exp(-e.deltaY * 0.0015));
}

/// Zooms by factor `f` about the stage's centre (keys: Ctrl/Cmd+= and Ctrl/Cmd+−).
export function zoomBy(f) {
  zoomAbout(stage.clientWidth / 2, stage.clientHeight / 2, f);
}

/// Zooms by factor `f` (within ZOOM_MIN…ZOOM_MAX) keeping the UV point under css (x, y) in place.
function zoomAbout(x, y, f) {
  const before = toUV(x, y);
  zoom = Math.min(Math.max(zoom * f, ZOOM_MIN), ZOOM_MAX);
  ox = x - before[0] * zoom * S();
  oy = y - before[1] * zoom * S();
  fitted = true;
  redraw();
}

/// Pans by (dx, dy) css px: the view moves that way over the UV square (keys: arrows with
/// nothing selected).
export function panBy(dx, dy) {
  ox -= dx;
  oy -= dy;
  fitted = true;
  redraw();
}

/// Where placement `id` is on screen (client px): centre, corners, rotation handle — for tests
/// and for scripted use; null when it is not drawn. A surface placement's centre is its anchor's
/// texel where it is drawn (during and just after a slide too).
export function screenGeometry(id) {
  const p0 = placementById(id);
  if (!p0 || !canvas) return null;
  const p = shown(p0);
  const r = canvas.getBoundingClientRect();
  const abs = ([x, y]) => [r.left + x, r.top + y];
  if (!geo.inTexture(p)) { // a surface placement: its anchor's texel and its pieces' bounds
    const o = outlineOf(p0), off = surfaceOffset(p0);
    return o && o.anchor_uv ? { center: abs(toScreen([o.anchor_uv[0] + off[0], o.anchor_uv[1] + off[1]])), bounds: (o.bounds || []).map((b) => [...abs(toScreen([b[0] + off[0], b[1] + off[1]])), ...abs(toScreen([b[2] + off[0], b[3] + off[1]]))]),
                                segments: o.segments.length, pxPerUV: zoom * S(), uvAt: (x, y) => toUV(x - r.left, y - r.top) } : null;
  }
  const hp = handlePoints(p);
  return { center: abs(toScreen(p.center)), corners: hp.corners.map(abs), rotate: abs(hp.rotate),
           pxPerUV: zoom * S(), uvAt: (x, y) => toUV(x - r.left, y - r.top) };
}

/// One texel of the height map in UV units (for nudges).
export const texelUV = () => 1 / heightmapSize()[0];
