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
// flight, the newest position next); the placement under the pick (a UV footprint holding the
// picked UV, or a surface decal holding the picked rest point) is outlined as hovered, and with the
// place tool on the brush (what a click would add: a circle on the body, or a UV footprint) is
// outlined there. The pick's surface position is also what the wheel zooms to.
//
// A drag that starts on the selected surface placement's decal moves it over the body (SPEC §8):
// its anchor follows the picks under the pointer (position and normal; its tangent kept where it
// can be), previewed in the frames, one edit and one undo step when the drag ends; Esc cancels.

import { store, set, placementById } from "./store.js";
import { focusPath } from "./scene_resource.js";
import * as geo from "./geometry.js";
import { Stream, patchPlacement, committingChange } from "./edits.js";
import { hold, release, withPending } from "./pending.js";

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

/// The world point under frame pixel `px` (of a square frame `size` pixels wide) that lies as far
/// along the view as world point `at`, for camera `from` (explicitCamera's numbers); null when `at`
/// lies behind the camera.
export function underPixelAtDepth(from, px, size, at) {
  const { dir, right, up } = basis(from.yaw, from.pitch);
  const eye = add(from.target, mul(dir, from.distance));
  const z = -dot(sub(at, eye), dir); // depth along the view (the camera looks along -dir)
  if (!(z > 0)) return null; // behind the camera now: nothing under the pixel at that depth
  const t = Math.tan(FOV_Y / 2);
  const sx = ((px[0] + 0.5) / size) * 2 - 1, sy = 1 - ((px[1] + 0.5) / size) * 2;
  return add(eye, add(mul(dir, -z), add(mul(right, sx * t * z), mul(up, sy * t * z))));
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
  const answer = await api.get(focusPath(store.sceneId, q));
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

/// Hover and brush state the frames outline: {hover: pid | null, brush: {uv: [u, v, su, sv, rot]}
/// | {surface: [x, y, z, nx, ny, nz, diameter]} | null}.
export const pointer = { hover: null, brush: null, last: null /* {px, hit, camera} of the last pick */ };

/// Wires the stage's pointer. `ctx`: {framePixel(e), displaySide(), pick(x, y), params(),
/// placeTool(), brushFor(pick), onClick(e), onChange(), onError(err)} from frame_view.js.
let cancelDecal = () => false;

/// Cancels a running decal drag in the 3D view (Esc; keys.js): the placement stays where it was.
/// True when one ran.
export const cancelDecalDrag = () => cancelDecal();

let stageEl = null;

export function initCamera(stage, theApi, ctx) {
  api = theApi;
  stageEl = stage;
  let drag = null;
  cancelDecal = () => {
    if (!drag || !drag.decal) return false;
    const d = drag.decal;
    drag = null;
    stage.classList.remove("moving");
    endDecalDrag(d, false, ctx);
    return true;
  };
  stage.addEventListener("contextmenu", (e) => { if (drag && drag.pan) e.preventDefault(); });
  stage.addEventListener("pointerdown", (e) => {
    if (e.button !== 0 && e.button !== 1) return;
    if (e.button === 1) e.preventDefault(); // no autoscroll
    stage.focus();
    const pan = e.button === 1 || e.shiftKey;
    drag = { x: e.clientX, y: e.clientY, button: e.button, pan, from: explicitCamera(), moved: false, pivot: null };
    const decal = !pan && e.button === 0 && !ctx.placeTool() && decalUnder(ctx.framePixel(e));
    if (decal) drag.decal = startDecalDrag(decal);
    else if (!pan) {
      // The pivot (the body point under the view's centre) may come after the orbit has begun:
      // the orbit so far is kept (it restarts from the camera it reached) and only this drag's.
      const d = drag;
      orbitPivot(ctx).then((p) => {
        if (drag !== d) return;
        if (d.moved) { d.from = explicitCamera(); d.x = d.lastX; d.y = d.lastY; }
        d.pivot = p;
      });
    }
    stage.setPointerCapture(e.pointerId);
  });
  stage.addEventListener("pointermove", (e) => {
    if (!drag) { hoverAt(e, ctx); return; }
    drag.lastX = e.clientX;
    drag.lastY = e.clientY;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (!drag.moved && Math.hypot(dx, dy) < 4) return;
    if (!drag.moved) { drag.moved = true; stage.classList.add(drag.decal ? "moving" : drag.pan ? "panning" : "orbiting"); }
    if (drag.decal) return moveDecal(drag.decal, ctx.framePixel(e), ctx);
    if (drag.pan) return panBy(dx, dy, ctx.displaySide(), drag.from);
    const c0 = drag.from || store.camera;
    const yaw = Math.round(geo.wrapDegrees(c0.yaw - dx * 0.5) * 10) / 10;
    const pitch = Math.round(Math.max(-85, Math.min(85, c0.pitch + dy * 0.4)) * 10) / 10;
    orbitAbout(drag.from, yaw, pitch, drag.pivot);
  });
  const end = (e) => {
    const d = drag;
    drag = null;
    stage.classList.remove("panning", "orbiting", "moving");
    if (d && d.decal) committingChange(() => endDecalDrag(d.decal, e.type === "pointerup" && d.moved, ctx));
    if (d && !d.moved && d.button === 0 && !d.pan && e.type === "pointerup") committingChange(() => ctx.onClick(e)); // a pick, then maybe a new placement
  };
  stage.addEventListener("pointerup", end);
  stage.addEventListener("pointercancel", end);
  stage.addEventListener("pointerleave", () => {
    if (drag) return;
    leaveGeneration++; // a pick still in flight is for a pointer that has gone
    wantedPick = null;
    pointer.last = null;
    stage.classList.remove("ondecal");
    setHover(null, null, ctx);
  });
  stage.addEventListener("wheel", (e) => {
    e.preventDefault();
    const factor = Math.exp(Math.max(-300, Math.min(300, e.deltaY)) * 0.001);
    const px = ctx.framePixel(e);
    const near = pointer.last && px && Math.hypot(pointer.last.px[0] - px[0], pointer.last.px[1] - px[1]) <= 3;
    // The zoom turns about the point under the pointer at the depth of the skin the last pick hit
    // there: that pick's own point when it was made with the camera shown now; after a camera
    // change (a pick answered after a newer tick) the point under the pointer now at that depth,
    // so that the zoom does not drift towards where the old point shows.
    const from = explicitCamera();
    const fresh = near && pointer.last.camera === cameraKey(ctx);
    const point = !near || !pointer.last.hit ? null : fresh || !from ? pointer.last.hit.position
      : underPixelAtDepth(from, px, ctx.params().width, pointer.last.hit.position);
    zoomAbout(factor, point);
    if (fresh) pointer.last.camera = cameraKey(ctx); // zooming about it keeps it under the pointer
    else hoverAt(e, ctx); // a pick with this camera for the next tick
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
  const camera = cameraKey(ctx);
  try {
    const hit = await ctx.pick(job.px[0], job.px[1]);
    if (generation !== leaveGeneration) return;
    pointer.last = { px: job.px, hit: hit.hit ? hit : null, camera };
    if (!hit.hit) setHover(null, null, ctx);
    else {
      const p = geo.hitPick(store.doc.placements.map(withPending), hit);
      setHover(p ? p.id : null, ctx.placeTool() ? ctx.brushFor(hit) : null, ctx);
    }
    stageEl.classList.toggle("ondecal", !ctx.placeTool() && !!decalUnder(job.px)); // a drag here moves it
  } catch { /* a pick that fails (scene gone, offline) only loses the hover */ }
  finally {
    picking = false;
    if (wantedPick) setTimeout(() => pumpPick(ctx), 40); // at most ~25 picks a second
  }
}

/// The camera a pick is made with, as a comparable string.
function cameraKey(ctx) {
  const p = ctx.params();
  return JSON.stringify([p.yaw, p.pitch, p.distance, p.target]);
}

function setHover(pid, brush, ctx) {
  if (pid === pointer.hover && JSON.stringify(brush) === JSON.stringify(pointer.brush)) return;
  pointer.hover = pid;
  pointer.brush = brush;
  ctx.onChange();
}

// --- dragging a surface placement over the body ------------------------------------------------

/// The selected surface placement under frame pixel `px` (by the last hover pick there), or null.
function decalUnder(px) {
  const last = pointer.last;
  if (!px || !last || !last.hit || Math.hypot(last.px[0] - px[0], last.px[1] - px[1]) > 3) return null;
  if (store.pinnedRevision !== null) return null; // an old revision is shown: no edits
  const p = pointer.hover && store.selection.includes(pointer.hover) ? placementById(pointer.hover) : null;
  return p && p.projection === "surface" ? p.id : null;
}

function startDecalDrag(id) {
  const orig = withPending(placementById(id));
  return { id, orig, value: null, pump: null, wanted: null, ended: false,
           stream: new Stream((fields) => patchPlacement(id, fields, { undoable: false }), { what: `move "${orig.label || orig.id}"` }) };
}

function moveDecal(d, px, ctx) {
  if (!px || d.ended) return;
  d.wanted = px;
  if (!d.pump) d.pump = pumpDecal(d, ctx).finally(() => { d.pump = null; });
}

/// Picks under the pointer while a decal drag runs (one in flight, the newest pixel next); each
/// answer on the body moves the decal (held: the frames preview it).
async function pumpDecal(d, ctx) {
  try {
    while (d.wanted && !d.ended) {
      const at = d.wanted;
      d.wanted = null;
      const hit = await ctx.pick(at[0], at[1]);
      if (d.ended) return;
      if (!hit.hit || !hit.anchor) continue; // off the body: the decal stays where it was
      d.value = { anchor: geo.anchorNear(d.orig, hit.anchor) };
      d.stream.send(d.value);
      hold(d.id, d.value); // the frames preview it until the one edit is answered
      ctx.onChange();
    }
  } catch (err) { ctx.onError(err); }
}

/// Ends a decal drag: `commit` sends the last position (after the picks still on their way: a
/// quick drag on a slow server still lands where the pointer let go), else puts it back.
async function endDecalDrag(d, commit, ctx) {
  if (commit && d.pump) await d.pump;
  d.ended = true;
  if (!commit || !d.value) {
    release(d.id);
    await d.stream.cancel();
    ctx.onChange();
    return;
  }
  await d.stream.finish();
  release(d.id, d.value);
  ctx.onChange();
}
