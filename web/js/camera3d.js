// 3D view camera and pointer: orbit (drag; about the selection's surface centre when a placement
// is selected), pan (middle drag or Shift+drag), zoom to the cursor (wheel: the skin under the
// pointer stays under it), frame the selection (F or the bar's Frame button: centre and zoom on the
// selected placement's surface region), and the pointer's hover and place-brush outlines.
//
// The camera is store.camera = {yaw, pitch, distance, target}: distance null = "auto", target
// null = the centre of the posed bounds, else a world point [x, y, z] (the frame routes' `target`).
// The same maths as the server's core/camera.hpp (30° vertical field of view, square frames, yaw 0
// looking along −z, world up +y): every camera change is exact numbers, so a permalink gives the
// same frame. Where the camera is "auto", moves start from the camera the last frame was rendered
// with (its X-Dermis-Camera-Distance / -Target headers: `resolvedCamera`).
//
// Hover and brush: pointer moves (no button) pick the skin under the pointer (GET pick, one in
// flight, the newest position next); the placement whose footprint holds the picked UV is outlined
// as hovered, and with the place tool on the brush (the footprint a click would add) is outlined
// there. The pick's surface position is also what the wheel zooms to.

import { store, set, placementById } from "./store.js";
import * as geo from "./geometry.js";

const FOV_Y = (30 * Math.PI) / 180;
const r4 = (x) => Math.round(x * 1e4) / 1e4;

/// What the last frame was rendered with: {distance, target} (null until a frame has shown).
export const resolvedCamera = { distance: null, target: null };

/// Reads the camera headers of a frame answer.
export function noteFrameCamera(headers) {
  const d = +headers.get("X-Dermis-Camera-Distance");
  const t = (headers.get("X-Dermis-Camera-Target") || "").split(",").map(Number);
  if (d > 0) resolvedCamera.distance = d;
  if (t.length === 3 && t.every(Number.isFinite)) resolvedCamera.target = t;
}

const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const mul = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => mul(a, 1 / Math.hypot(...a));

/// The camera basis of (yaw, pitch) as core/camera builds it: dir (target → eye), right, up.
export function basis(yaw, pitch) {
  const y = (yaw * Math.PI) / 180, p = (pitch * Math.PI) / 180;
  const dir = [Math.sin(y) * Math.cos(p), Math.sin(p), Math.cos(y) * Math.cos(p)];
  const worldUp = Math.abs(dir[1]) > 0.999 ? [0, 0, -dir[1]] : [0, 1, 0];
  const right = norm(cross(mul(dir, -1), worldUp));
  const up = cross(right, mul(dir, -1));
  return { dir, right, up };
}

/// The camera as numbers: store.camera with "auto" parts taken from the last frame (null when
/// nothing has been rendered yet).
export function explicitCamera() {
  const c = store.camera;
  const distance = c.distance ?? resolvedCamera.distance;
  const target = c.target ?? resolvedCamera.target;
  if (!distance || !target) return null;
  return { yaw: c.yaw, pitch: c.pitch, distance, target };
}

function setCamera(fields) {
  const c = { ...store.camera, ...fields };
  if (c.target) c.target = c.target.map(r4);
  if (c.distance !== null && c.distance !== undefined) c.distance = Math.min(Math.max(r4(c.distance), 0.001), 10000);
  set({ camera: c });
}

/// Pans by (dx, dy) screen pixels of a frame shown `side` pixels wide: the picture follows the pointer.
export function panBy(dx, dy, side, from = explicitCamera()) {
  if (!from) return;
  const { right, up } = basis(from.yaw, from.pitch);
  const perPixel = (2 * from.distance * Math.tan(FOV_Y / 2)) / side;
  setCamera({ target: add(from.target, add(mul(right, -dx * perPixel), mul(up, dy * perPixel))), distance: from.distance });
}

/// Zooms by `factor` (< 1: closer) about world point `point` (null: about the target), which
/// keeps its place in the picture: eye and target scale about it.
export function zoomAbout(factor, point) {
  const from = explicitCamera();
  if (!from) {
    const d = store.camera.distance ?? store.liveCamera?.distance ?? 3;
    return setCamera({ distance: d * factor });
  }
  const target = point ? add(point, mul(sub(from.target, point), factor)) : from.target;
  setCamera({ target, distance: from.distance * factor });
}

/// Orbits from camera `from` to (yaw, pitch) about world point `pivot`: the pivot keeps its place
/// in the picture (the target turns about it with the camera).
export function orbitAbout(from, yaw, pitch, pivot) {
  if (!from || !pivot) return setCamera({ yaw, pitch });
  const b0 = basis(from.yaw, from.pitch), b1 = basis(yaw, pitch);
  const rel = sub(from.target, pivot);
  const local = [dot(rel, b0.right), dot(rel, b0.up), dot(rel, b0.dir)];
  const target = add(pivot, add(add(mul(b1.right, local[0]), mul(b1.up, local[1])), mul(b1.dir, local[2])));
  setCamera({ yaw, pitch, target, distance: from.distance });
}

// --- the selection's surface region (GET focus) -----------------------------------------------

let api = null;
let focusCache = { key: "", answer: null };
const focusKey = (pid, params) => JSON.stringify([store.sceneId, pid, params.time, params.revision, placementById(pid)]);

/// {target, distance, radius} of placement `pid` for the frame `params` describe (cached).
export async function focusOf(pid, params) {
  const key = focusKey(pid, params);
  if (focusCache.key === key) return focusCache.answer;
  const q = new URLSearchParams({ placement: pid, time: String(params.time ?? 0) });
  if (params.revision) q.set("revision", String(params.revision));
  const answer = await api.get(`/scenes/${store.sceneId}/focus?${q}`);
  focusCache = { key, answer };
  return answer;
}

/// Centres and zooms the camera on the selected placement's surface region (F). False when
/// nothing is selected.
export async function frameSelection(params) {
  const pid = store.selection.find((id) => placementById(id));
  if (!pid) return false;
  const f = await focusOf(pid, params);
  setCamera({ target: f.target, distance: f.distance });
  return true;
}

// --- pointer: orbit, pan, wheel, hover, brush -------------------------------------------------

/// Hover and brush state the frames outline: {hover: pid | null, brush: [u, v, su, sv, rot] | null}.
export const pointer = { hover: null, brush: null, last: null /* {px, hit} of the last pick */ };

/// Wires the stage's pointer. `ctx`: {framePixel(e), displaySide(), pick(x, y), params(),
/// placeTool(), brushSize(), onClick(e), onChange(), onError(err)} from frame_view.js.
export function initCamera(stage, theApi, ctx) {
  api = theApi;
  let drag = null;
  stage.addEventListener("contextmenu", (e) => { if (drag && drag.pan) e.preventDefault(); });
  stage.addEventListener("pointerdown", (e) => {
    if (e.button !== 0 && e.button !== 1) return;
    if (e.button === 1) e.preventDefault(); // no autoscroll
    stage.focus();
    const pan = e.button === 1 || e.shiftKey;
    drag = { x: e.clientX, y: e.clientY, button: e.button, pan, from: explicitCamera(), moved: false, pivot: null };
    if (!pan) orbitPivot(ctx).then((p) => { if (drag) drag.pivot = p; });
    stage.setPointerCapture(e.pointerId);
  });
  stage.addEventListener("pointermove", (e) => {
    if (!drag) { hoverAt(e, ctx); return; }
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (!drag.moved && Math.hypot(dx, dy) < 4) return;
    if (!drag.moved) { drag.moved = true; stage.classList.add(drag.pan ? "panning" : "orbiting"); }
    if (drag.pan) return panBy(dx, dy, ctx.displaySide(), drag.from);
    const c0 = drag.from || store.camera;
    const yaw = Math.round(geo.wrapDegrees(c0.yaw - dx * 0.5) * 10) / 10;
    const pitch = Math.round(Math.max(-85, Math.min(85, c0.pitch + dy * 0.4)) * 10) / 10;
    orbitAbout(drag.from, yaw, pitch, drag.pivot);
  });
  const end = (e) => {
    const d = drag;
    drag = null;
    stage.classList.remove("panning", "orbiting");
    if (d && !d.moved && d.button === 0 && !d.pan && e.type === "pointerup") ctx.onClick(e);
  };
  stage.addEventListener("pointerup", end);
  stage.addEventListener("pointercancel", end);
  stage.addEventListener("pointerleave", () => {
    if (drag) return;
    leaveGeneration++; // a pick still in flight is for a pointer that has gone
    wantedPick = null;
    pointer.last = null;
    setHover(null, null, ctx);
  });
  stage.addEventListener("wheel", (e) => {
    e.preventDefault();
    const factor = Math.exp(Math.max(-300, Math.min(300, e.deltaY)) * 0.001);
    const px = ctx.framePixel(e);
    const near = pointer.last && px && Math.hypot(pointer.last.px[0] - px[0], pointer.last.px[1] - px[1]) <= 3;
    zoomAbout(factor, near && pointer.last.hit ? pointer.last.hit.position : null);
    if (!near) hoverAt(e, ctx); // the next tick zooms about the skin there
  }, { passive: false });
  document.addEventListener("keydown", (e) => {
    if (e.key !== "f" && e.key !== "F") return;
    if (e.ctrlKey || e.metaKey || e.altKey || document.querySelector("dialog[open]")) return;
    const el = document.activeElement;
    if (el && (el.tagName === "INPUT" && !["range", "checkbox", "button"].includes(el.type) || el.tagName === "TEXTAREA" || el.tagName === "SELECT" || el.isContentEditable)) return;
    e.preventDefault();
    frameSelection(ctx.params()).catch((err) => ctx.onError(err));
  });
}

/// The point an orbit turns about: the selected placement's surface centre, else the target.
async function orbitPivot(ctx) {
  const pid = store.selection.find((id) => placementById(id));
  if (!pid) return null;
  try { return (await focusOf(pid, ctx.params())).target; } catch { return null; }
}

// Picks for hover: one in flight, the newest pointer position next. A pick that lands after the
// pointer left the stage is dropped (it would outline a placement nobody points at).
let picking = false, wantedPick = null, leaveGeneration = 0;

function hoverAt(e, ctx) {
  const px = ctx.framePixel(e);
  if (!px) { pointer.last = null; setHover(null, null, ctx); return; }
  wantedPick = { px };
  pumpPick(ctx);
}

async function pumpPick(ctx) {
  if (picking || !wantedPick || !store.doc) return;
  const job = wantedPick;
  wantedPick = null;
  picking = true;
  const generation = leaveGeneration;
  try {
    const hit = await ctx.pick(job.px[0], job.px[1]);
    if (generation !== leaveGeneration) return;
    pointer.last = { px: job.px, hit: hit.hit ? hit : null };
    if (!hit.hit) setHover(null, null, ctx);
    else {
      const p = geo.hit(store.doc.placements, hit.uv);
      const size = ctx.brushSize();
      setHover(p ? p.id : null, ctx.placeTool() && size ? [r4(hit.uv[0]), r4(hit.uv[1]), size[0], size[1], 0] : null, ctx);
    }
  } catch { /* a pick that fails (scene gone, offline) only loses the hover */ }
  finally {
    picking = false;
    if (wantedPick) setTimeout(() => pumpPick(ctx), 40); // at most ~25 picks a second
  }
}

function setHover(pid, brush, ctx) {
  if (pid === pointer.hover && JSON.stringify(brush) === JSON.stringify(pointer.brush)) return;
  pointer.hover = pid;
  pointer.brush = brush;
  ctx.onChange();
}
