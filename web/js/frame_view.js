// 3D view: the server's frames of the scene. The camera (orbit, pan, zoom to the cursor, frame
// the selection, hover and brush outlines, dragging a decal) is camera3d.js; click selects the
// placement under the pointer (pick → UV footprint or surface decal), and with the place tool (P,
// or Alt+click) creates one there with the suggested driver: a surface placement (SPEC §8: anchor
// from the hit, tangent across the driver's bone, a square decal the brush's diameter wide in model
// units; [ and ] size the brush while the tool is on) or, with "Place as: in the texture", a UV
// placement at the hit's UV. The selection is outlined on the skin (frame `highlight`), the hovered
// placement too (`hover`), and the place tool's brush (`surface_brush`: a circle on the body, or
// `brush`: a UV footprint) — with the tool off, `surface_brush` outlines the Propose… panel's
// current proposal instead (its ghost). View modes shaded (the scene's shading), pbr / skin (that
// shading for this view; with a shadowed key light: pbr-key / skin-key) and bump / displacement / normal; compare with a split slider, flicker,
// or the diff heat map against "patterns off" or a chosen revision (compare images carry no
// outlines). The bar's Turntable button shows the selection's range of
// motion as an animated WebP (GET turntable).
//
// While a drag runs in the texture view, frames preview the dragged placement (the frame route's
// `preview`: nothing stored) at each pointer move, with MSAA off; the edits go to the server at
// their own pace. Frames are coalesced: the newest wanted URL wins, the state changes of one
// moment ask for one frame, and a frame never replaces a newer one (stale answers are dropped);
// a frame slower than 500 ms shows a spinner. When no gesture runs, one request is in flight per
// image. While a gesture runs (a drag in either view, a slider, a key burst) the 3D view keeps
// several in flight, paced to the server's own time per frame (its `Server-Timing`), so that over
// a slow link frames keep coming at the server's rate instead of one per round trip (FrameLoader
// below; docs/remote-authoring.md); on loopback that stays one. The texture view never waits for
// the network: it draws on the client.

import { store, on, set, emit, shownTime, whenIdle, placementById, Topic } from "./store.js";
import { API } from "./api.js";
import { framePath, frameDiffPath, pickPath, turntableUrl, fetchRevisions } from "./scene_resource.js";
import * as geo from "./geometry.js";
import { notify } from "./notice.js";
import { addPlacement } from "./edits.js";
import { placementFromPattern, surfacePlacementFromPattern, applySuggested } from "./placing.js";
import { trace } from "./trace.js";
import { frameFormat } from "./frame_format.js";
import { initCamera, noteFrameCamera, pointer, frameSelection, resolvedCamera } from "./camera3d.js";

let api, stage, img, cmpImg, spinner, splitHandle, sizeSelect;
let flickerTimer = null;
let placeTool = false;
let placeAs = "surface"; // "surface" (on the body, SPEC §8) | "uv" (in the texture)
let brushDiameter = null; // model units; null until the first frame gives the model's scale
const FRAME_SIZES = [384, 512, 768, 1024];
export let frameSize = 512;
/// Frame statistics for tests and benchmarks (window.dermisEditor.frameStats): frames shown and
/// requested, answers dropped as stale, the most requests of the 3D view in flight at once
/// (`peakInFlight`, a test may reset it), the pipeline's estimates (server ms per frame, the rest
/// of a round trip, k) and `inFlightLimit`: null (adaptive), or a cap on the requests in flight
/// (1: one at a time, the editor before pipelining — the benchmark's "before").
export const frameStats = { shown: 0, requested: 0, dropped: 0, times: [], peakInFlight: 0, inFlightLimit: null, pipeline: null };

// Pipelining (issue #28, docs/remote-authoring.md): over a slow link one request in flight gives
// one frame per round trip (100 ms RTT: ~6–9 frames/s). While `pipelined()` (a gesture: a drag in
// the texture view, a decal drag, a slider, a key burst; or a drag on the 3D stage) the loader
// keeps up to k requests in flight and issues a new one only when the wanted URL is new and at
// least PACE·S ms passed since the last issue. S is the server's time per frame: the median of the
// last answers' `Server-Timing: render;dur=`, which counts the wait in the server's render queue,
// so requests issued faster than it renders raise S and slow the pace (no queue builds up). rtt is
// the rest of a request's time (EWMA of fetch → body − dur), and k = 1 + floor(rtt / S), 1..4: one
// more request per whole frame the server can render while an answer travels. On loopback the
// rest (8–25 ms here, S 20–30) is mostly CPU work on the cores the server renders with, not
// waiting, and overlapping it only made frames older (k = 2 there: 105–123 ms instead of 78–84
// on a busy machine): k stays 1 there, as before. Stale requests are not aborted (that closes
// an HTTP/1.1 connection: a new handshake at RTT); their answers are dropped. Chromium opens 6
// connections per host: the event stream, ≤ 4 frames and an edit.
const MAX_IN_FLIGHT = 4;
const PACE = 0.9;    // the pace's share of S: a little faster than the server, so it never idles
const EWMA = 0.25;   // weight of a new sample in rtt
const S_WINDOW = 9;  // answers in S's median

/// The server's time of a frame answer (`Server-Timing: render;dur=<ms>`), or null.
function serverDur(headers) {
  const m = /(?:^|,)\s*render\s*;[^,]*\bdur=([\d.]+)/.exec(headers.get("Server-Timing") || "");
  return m ? +m[1] : null;
}

const median = (xs) => { const v = [...xs].sort((a, b) => a - b); return v.length ? v[v.length >> 1] : null; };

/// Runs fn in a task of its own soon (no timer clamping): the state changes of one moment (a
/// gesture's end: its revision, its end, its preview released) ask for one frame, the last.
const soon = (() => {
  const ch = new MessageChannel();
  const queue = [];
  ch.port1.onmessage = () => { for (const fn of queue.splice(0)) fn(); };
  return (fn) => { if (queue.push(fn) === 1) ch.port2.postMessage(0); };
})();

/// Loads URLs into one <img>: the newest wanted URL wins and a frame never replaces a newer one
/// on screen. Idle: at most one request in flight (the newest wanted URL next). While
/// `pipelined()`: up to k in flight, paced (above); `onShown` runs after a frame is on screen.
class FrameLoader {
  constructor(el, onShown, pipelined = () => false) {
    this.el = el;
    this.onShown = onShown;
    this.pipelined = pipelined;
    this.wanted = null;         // {url, seq, t0}: not asked for yet
    this.inFlight = new Set();  // jobs asked for, not on screen (or dropped) yet
    this.newest = null;         // the newest job asked for
    this.shownSeq = 0;
    this.seq = 0;
    this.url = null;            // the URL on screen
    this.objectUrl = null;
    this.slowTimer = null;
    this.paceTimer = null;
    this.pumpSoon = false;
    this.lastIssue = -Infinity;
    this.showing = Promise.resolve(); // frames go on screen one at a time, in answer order
    this.durs = { pipelined: [], idle: [] }; // the last Server-Timing durs, per mode
    this.rttMs = null;
  }
  load(url) {
    // The newest request asked for this URL: its answer is the next one to go on screen.
    if (this.newest && this.newest.url === url && !this.newest.failed) { this.wanted = null; return; }
    this.wanted = { url, seq: ++this.seq, t0: performance.now() };
    if (!this.pumpSoon) { this.pumpSoon = true; soon(() => { this.pumpSoon = false; this.pump(); }); }
  }
  /// S: the server's time per frame while pipelining, in ms (null: not measured yet).
  serverTime() {
    return median(this.durs.pipelined.length ? this.durs.pipelined : this.durs.idle);
  }
  /// How many requests may be in flight now, and the pace (ms between issues) while pipelining.
  budget() {
    const cap = Math.max(1, Math.min(MAX_IN_FLIGHT, frameStats.inFlightLimit ?? MAX_IN_FLIGHT));
    if (!this.pipelined()) return { pipelined: false, k: 1, cap, gap: 0 };
    const S = this.serverTime();
    return { pipelined: true, k: this.depth(cap), cap, gap: S ? PACE * S : 0 };
  }
  /// k: requests in flight that keep the server busy over the round trip (1 until measured).
  depth(cap) {
    const S = this.serverTime();
    const k = S && this.rttMs !== null ? 1 + Math.floor(this.rttMs / Math.max(S, 1)) : 1;
    return Math.max(1, Math.min(cap, k));
  }
  pump() {
    if (!this.wanted) return;
    const b = this.budget();
    if (b.pipelined) {
      if (this.inFlight.size >= b.k) return; // an answer calls pump again
      const wait = b.k > 1 ? this.lastIssue + b.gap - performance.now() : 0;
      if (wait > 0) {
        if (!this.paceTimer) this.paceTimer = setTimeout(() => { this.paceTimer = null; this.pump(); }, wait);
        return;
      }
    } else {
      // Idle: one at a time; the requests of a gesture that just ended do not hold up its final
      // frame (they are stale: their answers are dropped), within the cap.
      if (this.inFlight.size >= b.cap || [...this.inFlight].some((j) => !j.pipelined)) return;
    }
    const job = this.wanted;
    this.wanted = null;
    this.run(job, b.pipelined);
  }
  async run(job, pipelined) {
    job.pipelined = pipelined;
    job.issuedAt = this.lastIssue = performance.now();
    this.newest = job;
    this.inFlight.add(job);
    frameStats.requested++;
    frameStats.peakInFlight = Math.max(frameStats.peakInFlight, this.inFlight.size);
    if (!this.slowTimer) this.slowTimer = setTimeout(() => { spinner.hidden = false; }, 500);
    let answer = null;
    try {
      const r = await fetchFrame(job.url);
      if (this.onCamera && job.seq > this.shownSeq) this.onCamera(r.headers);
      const blob = await r.blob();
      job.bodyAt = performance.now();
      job.dur = serverDur(r.headers);
      this.learn(job);
      answer = { blob, changed: r.headers.get("X-Dermis-Changed-Pixels") };
    } catch (e) {
      job.failed = true;
      if (job.seq > this.shownSeq && (e.status !== 0 || store.online)) notify(`Frame: ${e.message}`, "error");
    }
    if (answer && job.seq > this.shownSeq) await this.show(job, answer);
    else if (answer) frameStats.dropped++;
    // A request counts until its frame is on screen (or dropped): the next render then does not
    // compete with this decode for the CPU (measured: frames 10–15 ms older without this on
    // loopback, where the server and the browser share the cores).
    this.inFlight.delete(job);
    if (!this.inFlight.size) this.quiet();
    this.pump();
  }
  /// Folds a finished request into S and rtt.
  learn(job) {
    if (job.dur === null || !Number.isFinite(job.dur)) return;
    const durs = this.durs[job.pipelined ? "pipelined" : "idle"];
    durs.push(job.dur);
    if (durs.length > S_WINDOW) durs.shift();
    const rest = Math.max(0, job.bodyAt - job.issuedAt - job.dur);
    this.rttMs = this.rttMs === null ? rest : this.rttMs + EWMA * (rest - this.rttMs);
    if (this.onShown) frameStats.pipeline = { serverMs: +this.serverTime().toFixed(1), rttMs: +this.rttMs.toFixed(1), k: this.depth(this.budget().cap) };
  }
  quiet() {
    clearTimeout(this.slowTimer);
    this.slowTimer = null;
    spinner.hidden = true;
  }
  show(job, { blob, changed }) {
    this.showing = this.showing.then(async () => {
      if (job.seq <= this.shownSeq) { frameStats.dropped++; return; } // a newer frame went on screen first
      const objectUrl = URL.createObjectURL(blob);
      await new Promise((resolve) => { this.el.onload = this.el.onerror = resolve; this.el.src = objectUrl; });
      if (this.objectUrl) URL.revokeObjectURL(this.objectUrl);
      this.objectUrl = objectUrl;
      this.shownSeq = job.seq;
      this.url = job.url;
      this.el.dataset.url = job.url;
      this.el.dataset.changedPixels = changed || "";
      this.quiet(); // the spinner again when the next frame takes 500 ms
      if (this.inFlight.size > 1) this.slowTimer = setTimeout(() => { spinner.hidden = false; }, 500);
      this.onShown && this.onShown(job, performance.now());
    }).catch((e) => console.error(e));
    return this.showing;
  }
}

let mainLoader, cmpLoader;

/// The frame parameters of the view mode: "shaded" is the scene's own shading (none), "pbr",
/// "skin" and "legacy" a shading for this view (`shading=`), "pbr-key" and "skin-key" that shading with a
/// shadowed key light (`key_light=on`: the scene's, or the default one), the others an unlit view
/// of the maps (`view=`).
function viewParams() {
  if (store.view === "shaded") return {};
  if (store.view === "pbr" || store.view === "skin" || store.view === "legacy") return { shading: store.view };
  if (store.view === "pbr-key" || store.view === "skin-key") return { shading: store.view.slice(0, -4), key_light: "on" };
  return { view: store.view };
}

export function initFrameView(section, theApi) {
  api = theApi;
  section.innerHTML = `
    <div class="viewbar">
      <span class="title">3D</span>
      <label><span class="lbl">View</span> <select id="viewMode" aria-label="view mode" title="View mode">
        <option value="shaded" title="the scene's own shading">shaded</option>
        <option value="pbr" title="the character's glTF material under image-based light">pbr</option>
        <option value="skin" title="pbr with light scattered under the skin: how a wrinkle reads on skin">skin</option>
        <option value="pbr-key" title="pbr with a key light and its shadows (the scene's render.key_light, or the default one)">pbr + key light</option>
        <option value="skin-key" title="skin with a key light and its shadows: a wrinkle under one hard light">skin + key light</option>
        <option value="legacy" title="the old default shading (one Blinn-Phong light, base colour only), for comparisons">legacy</option>
        <option value="bump">bump</option>
        <option value="displacement">displacement</option><option value="normal">normal</option></select></label>
      <label><span class="lbl keep">Compare</span> <select id="compareMode" aria-label="compare mode" title="Compare with another frame: split, flicker, or a diff heat map">
        <option value="off">off</option><option value="split">split</option>
        <option value="flicker">flicker</option><option value="diff" title="diff heat map">diff</option></select></label>
      <span class="comparebits">
        <label id="compareAgainstLabel" hidden><span class="lbl">against</span> <select id="compareAgainst" aria-label="compare against" title="Compare against"><option value="off">patterns off</option></select></label>
        <input id="split" type="range" min="0" max="1" step="0.01" value="0.5" aria-label="split position" hidden>
        <span id="diffText" class="badge" title="pixels that differ" hidden></span>
      </span>
      <button type="button" id="placeTool" aria-pressed="false" title="Place tool (P): click the model to add a placement there">Place</button>
      <div class="more" id="viewMoreWrap">
        <button type="button" id="viewMore" class="morebutton" aria-expanded="false" aria-controls="viewMoreMenu" aria-label="more 3D view settings" title="More: frame size, reset camera, frame the selection, turntable">⋯</button>
        <div class="moremenu" id="viewMoreMenu" role="group" aria-label="more 3D view settings">
          <label><span class="lbl">Size</span> <select id="frameSize" aria-label="frame size" title="Frame size (pixels)">${FRAME_SIZES.map((s) => `<option>${s}</option>`).join("")}</select></label>
          <label><span class="lbl">Place as</span> <select id="placeAs" aria-label="place as" title="What the place tool adds: a decal on the body (a surface placement: seamless, in model units) or a footprint in the texture (a UV placement)"><option value="surface">on the body</option><option value="uv">in the texture</option></select></label>
          <button type="button" id="resetCamera" title="Reset the camera (orbit about the whole character)">Reset</button>
          <button type="button" id="frameSelection" title="Frame the selection (F): centre and zoom on the selected placement's skin" disabled>Frame</button>
          <button type="button" id="turntable" title="Turntable: the selection's range of motion (θmin → θmax → θmin) while the camera turns, as an animated WebP" disabled>Turntable</button>
        </div>
      </div>
    </div>
    <div class="stage" id="frameStage" tabindex="0" aria-label="3D view: drag to orbit, Shift+drag or middle drag to pan, wheel to zoom at the pointer, F frames the selection, click to select">
      <img id="frame" alt="" draggable="false">
      <img id="compareFrame" alt="" draggable="false" hidden>
      <div class="split-handle" hidden></div>
      <div class="spinner" hidden></div>
      <div class="stagehint" id="placeHint" role="status" hidden></div>
    </div>`;
  stage = section.querySelector(".stage");
  img = section.querySelector("#frame");
  cmpImg = section.querySelector("#compareFrame");
  spinner = section.querySelector(".spinner");
  splitHandle = section.querySelector(".split-handle");
  sizeSelect = section.querySelector("#frameSize");
  sizeSelect.value = String(frameSize);
  // Frames pipeline while a gesture runs (store.gestures: a drag, a slider, a key burst) or the
  // pointer drags on the 3D stage (orbit, pan, a decal).
  let stageDrag = false;
  mainLoader = new FrameLoader(img, (job, now) => {
    frameStats.shown++;
    if (trace.on) trace.frames.push({ t0: job.t0, shownAt: now, issuedAt: job.issuedAt, bodyAt: job.bodyAt, seq: job.seq, dur: job.dur, pipelined: job.pipelined,
                                      side: +((/[?&]width=(\d+)/.exec(job.url) || [])[1] || 0) });
    frameStats.times.push(now - job.t0);
    if (frameStats.times.length > 1000) frameStats.times.shift();
    img.alt = "rendered frame";
    if (store.compare.mode === "diff") document.getElementById("diffText").textContent = `${img.dataset.changedPixels || "?"} px changed`;
    img.dataset.seq = String(job.seq);
  }, () => store.gestures > 0 || stageDrag);
  mainLoader.onCamera = noteFrameCamera;
  cmpLoader = new FrameLoader(cmpImg);
  const $ = (id) => section.querySelector("#" + id);
  $("viewMode").onchange = (e) => set({ view: e.target.value });
  $("compareMode").onchange = (e) => set({ compare: { ...store.compare, mode: e.target.value } });
  $("compareAgainst").onchange = (e) => set({ compare: { ...store.compare, against: e.target.value } });
  $("split").oninput = (e) => { set({ compare: { ...store.compare, split: +e.target.value } }); layoutCompare(); };
  sizeSelect.onchange = () => { frameSize = +sizeSelect.value; refresh(); };
  $("placeTool").onclick = () => setPlaceTool(!placeTool);
  $("placeAs").onchange = (e) => { placeAs = e.target.value; pointer.brush = null; showPlaceHint(); refresh(); };
  $("resetCamera").onclick = () => set({ camera: { yaw: 0, pitch: 10, distance: null, target: null } });
  $("frameSelection").onclick = () => frameSelection(frameParams()).catch((e) => notify(`Frame: ${e.message}`, "error"));
  $("turntable").onclick = () => openTurntable();
  initMoreMenu($("viewMoreWrap"));
  initCamera(stage, api, {
    framePixel, displaySide, pick: pickAt, params: frameParams, placeTool: () => placeTool,
    brushFor, // the brush outlined where a pick hit
    onClick: click, onChange: refresh, onError: (e) => notify(`Frame: ${e.message}`, "error"),
  });
  stage.addEventListener("pointerdown", (e) => { if (e.button === 0 || e.button === 1) stageDrag = true; });
  const stageDragEnd = () => { if (stageDrag) { stageDrag = false; mainLoader.pump(); } };
  for (const type of ["pointerup", "pointercancel", "lostpointercapture"]) stage.addEventListener(type, stageDragEnd);
  on([Topic.SELECTION, Topic.DOC, Topic.SCENE], () => {
    const has = store.selection.some((id) => placementById(id));
    $("frameSelection").disabled = !has;
    $("turntable").disabled = !has;
  });
  on([Topic.DOC, Topic.REVISION, Topic.CAMERA, Topic.VIEW, Topic.COMPARE, Topic.SOLO, Topic.TIME, Topic.PINNED_REVISION, Topic.GESTURES,
      Topic.DRAG, Topic.SELECTION, Topic.GHOST], () => {
    $("viewMode").value = store.view;
    $("compareMode").value = store.compare.mode;
    $("split").hidden = store.compare.mode !== "split";
    $("compareAgainstLabel").hidden = store.compare.mode === "off"; // "against" means nothing until comparing
    if (store.compare.against === "off") $("compareAgainst").value = "off"; // a revision shows once fillAgainst lists it
    refresh();
  });
  on(Topic.REVISION, () => whenIdle("compare-list", fillAgainst, 400));
  on([Topic.CURRENT_PATTERN, Topic.PATTERNS], showPlaceHint);
}

/// The view bar's ⋯ menu (Size, Place as, Reset, Frame, Turntable): where the bar's row does
/// not fit its width those controls fold into it (the bar gets the class "fold"), elsewhere they
/// sit in the bar and ⋯ is hidden. The fit is measured again whenever the bar resizes or what it
/// shows changes (the compare extras, a label, the window's words). Enter, Space or ↓ on ⋯ opens
/// it with the focus on its first control; Esc closes it (the focus back on ⋯), as do a click or
/// the focus elsewhere.
function initMoreMenu(wrap) {
  const bar = wrap.closest(".viewbar");
  const fit = () => {
    bar.classList.remove("fold");
    if (bar.scrollWidth > bar.clientWidth + 1) bar.classList.add("fold");
  };
  fit();
  if (typeof ResizeObserver === "function") new ResizeObserver(fit).observe(bar);
  // Not the bar's own class: the observer would see its own change.
  new MutationObserver(fit).observe(bar, { subtree: true, childList: true, characterData: true, attributes: true, attributeFilter: ["hidden"] });
  const button = wrap.querySelector(".morebutton");
  const open = (yes, focusBack = false) => {
    wrap.classList.toggle("open", yes);
    button.setAttribute("aria-expanded", String(yes));
    if (yes) wrap.querySelector(".moremenu select:not(:disabled), .moremenu button:not(:disabled)")?.focus();
    else if (focusBack) button.focus();
  };
  button.onclick = () => open(!wrap.classList.contains("open"));
  button.addEventListener("keydown", (e) => {
    if (e.key === "ArrowDown" && !wrap.classList.contains("open")) { e.preventDefault(); open(true); }
  });
  wrap.addEventListener("keydown", (e) => {
    if (e.key === "Escape" && wrap.classList.contains("open")) { e.preventDefault(); e.stopPropagation(); open(false, true); }
  });
  wrap.addEventListener("focusout", (e) => { if (!wrap.contains(e.relatedTarget)) open(false); });
  document.addEventListener("pointerdown", (e) => { if (!wrap.contains(e.target)) open(false); });
}

/// Sets the frame size (one of 384, 512, 768, 1024; a permalink's size).
export function setFrameSize(n) {
  if (!FRAME_SIZES.includes(n)) return;
  frameSize = n;
  if (sizeSelect) sizeSelect.value = String(n);
  refresh();
}

export const placeToolOn = () => placeTool;

/// The surface brush's diameter in model units: set by resizeBrush, else a 40th of the camera's
/// distance when the whole body is framed (about an elbow crease on a person).
export function brushSize() {
  if (brushDiameter === null && resolvedCamera.distance) brushDiameter = roundSize(resolvedCamera.distance / 40);
  return brushDiameter;
}
const roundSize = (x) => Number(x.toPrecision(2));

/// Scales the surface brush by `factor` ([ and ] with the place tool on).
export function resizeBrush(factor) {
  const d = brushSize();
  if (!d) return;
  brushDiameter = Math.min(Math.max(roundSize(d * factor), 1e-4), 10000);
  if (pointer.brush && pointer.brush.surface) pointer.brush = { ...pointer.brush, surface: [...pointer.brush.surface.slice(0, 6), brushDiameter] };
  showPlaceHint();
  refresh();
}

/// The place tool's brush at pick answer `hit`: {surface: [x, y, z, nx, ny, nz, diameter]} on the
/// body, {uv: [u, v, su, sv, rotation]} in the texture, or null (no pattern chosen).
function brushFor(hit) {
  if (!currentPattern()) return null;
  if (placeAs === "surface" && hit.anchor) {
    const d = brushSize();
    return d ? { surface: [...hit.anchor.position, ...hit.anchor.normal].map((x) => Math.round(x * 1e5) / 1e5).concat([d]) } : null;
  }
  return { uv: [Math.round(hit.uv[0] * 1e4) / 1e4, Math.round(hit.uv[1] * 1e4) / 1e4, 0.08, 0.08, 0] }; // placementFromPattern's footprint
}

export function setPlaceTool(onOff) {
  placeTool = onOff;
  if (!onOff && pointer.brush) { pointer.brush = null; refresh(); }
  document.getElementById("placeTool").setAttribute("aria-pressed", String(onOff));
  stage.style.cursor = onOff ? "copy" : "";
  showPlaceHint();
}

/// While the place tool is on, the 3D view says what a click adds and how to leave the tool.
function showPlaceHint() {
  const hint = document.getElementById("placeHint");
  if (!hint) return;
  hint.hidden = !placeTool;
  if (!placeTool) return;
  const p = currentPattern();
  const how = placeAs === "surface" && brushSize() ? ` (on the body, ${brushSize()} units wide · [ ] size)` : placeAs === "uv" ? " (in the texture)" : "";
  hint.textContent = p ? `Place tool: click the model to add "${p.name || p.id}" there${how} · P or Esc to stop`
                       : "Place tool: choose a pattern in the library first · P or Esc to stop";
}

/// The frame parameters this view shows (shared by frame, compare, diff and pick); `outlines`
/// false leaves out the selection, hover and brush outlines (compare images, diff, pick).
export function frameParams(outlines = true) {
  const c = store.camera;
  const selected = store.doc ? store.selection.filter((id) => placementById(id)).slice(0, 6) : [];
  const hover = pointer.hover && placementById(pointer.hover) && !selected.includes(pointer.hover) ? pointer.hover : undefined;
  return {
    width: frameSize, height: frameSize,
    msaa: store.gestures > 0 ? 1 : undefined, // while dragging: quicker frames; the scene's MSAA after
    format: frameFormat(store.gestures > 0), // JPEG previews while dragging, lossless after (frame_format.js)
    yaw: c.yaw, pitch: c.pitch, distance: c.distance ?? undefined,
    target: c.target ? c.target.join(",") : undefined,
    time: shownTime(),
    ...viewParams(),
    only: store.solo.length ? store.solo.join(",") : undefined,
    revision: store.pinnedRevision ?? store.revision,
    preview: previewSource() ? JSON.stringify(previewSource()) : undefined,
    highlight: outlines && selected.length ? selected.join(",") : undefined,
    hover: outlines ? hover : undefined,
    brush: outlines && placeTool && pointer.brush && pointer.brush.uv ? pointer.brush.uv.join(",") : undefined,
    surface_brush: !outlines ? undefined : placeTool && pointer.brush && pointer.brush.surface ? pointer.brush.surface.join(",") : ghostBrush(),
  };
}

/// The URL (under /api/v1) of the frame this view shows now.
/// GETs a frame URL; a /frame URL too long for the server's 8 KB request line (a large preview)
/// goes as POST /frame with the same parameters in a JSON body — the same bytes come back.
function fetchFrame(url) {
  if (url.length <= 6000 || !/\/frame\?/.test(url)) return api.raw("GET", url);
  const [path, q] = url.split("?");
  const body = {};
  for (const [k, v] of new URLSearchParams(q)) body[k] = k === "preview" ? JSON.parse(v) : v;
  return api.raw("POST", path, { body });
}

// Over a slow link a gesture's previews are half the frame's side (issue #28): a quarter of the
// pixels to render (llvmpipe, measured in the latency test: 25–34 → 16–19 ms a preview, queueing
// included), encode, send (~19 → ~8 KB of JPEG: 8 → 3 ms at 20 Mbit/s) and decode, which is what a frame's age over RTT is made of there
// (docs/remote-authoring.md "Where the time goes"). The <img> scales it to the view; the frame
// after the gesture is full size and lossless. "Slow" is the pipeline's rtt estimate (the rest of
// a request beside the server's time) above REMOTE_RTT_MS: loopback measures 8–25 ms and keeps
// full-size previews, a 100 ms round trip ~120 ms.
const REMOTE_RTT_MS = 50;

/// The frame parameters the 3D view loads now: frameParams(), at half size during a gesture
/// over a slow link (above).
function shownParams(outlines) {
  const p = frameParams(outlines);
  const slow = mainLoader && mainLoader.rttMs !== null && mainLoader.rttMs >= REMOTE_RTT_MS;
  if (!(store.gestures > 0) || !slow) return p;
  // The scene's anti-aliasing, not frameParams' msaa=1: a 2× upscale doubles every stair of an
  // unsmoothed edge (on llvmpipe the post pass costs ~0.7 ms at 256²).
  const side = Math.max(128, Math.round(frameSize / 2));
  return { ...p, width: side, height: side, msaa: undefined };
}

export function frameUrl() {
  return framePath(store.sceneId, shownParams(store.compare.mode === "off"));
}

export function refresh() {
  if (!store.sceneId || !store.doc) return;
  const cmp = store.compare;
  const p = shownParams(cmp.mode === "off");
  const against = cmp.against === "off" ? { patterns: "off" } : { revision: +cmp.against };
  if (cmp.mode === "diff") {
    mainLoader.load(frameDiffPath(store.sceneId, { ...p, against: cmp.against }));
  } else {
    mainLoader.load(framePath(store.sceneId, p));
  }
  if (cmp.mode === "split" || cmp.mode === "flicker") cmpLoader.load(framePath(store.sceneId, { ...p, ...against }));
  layoutCompare();
}

function layoutCompare() {
  const mode = store.compare.mode;
  cmpImg.hidden = mode !== "split" && mode !== "flicker";
  splitHandle.hidden = mode !== "split";
  clearInterval(flickerTimer);
  flickerTimer = null;
  if (mode === "split") {
    const pct = store.compare.split * 100;
    cmpImg.style.clipPath = `inset(0 0 0 ${pct}%)`;
    cmpImg.style.visibility = "visible";
    splitHandle.style.left = `${pct}%`;
  } else if (mode === "flicker") {
    cmpImg.style.clipPath = "";
    flickerTimer = setInterval(() => { cmpImg.style.visibility = cmpImg.style.visibility === "hidden" ? "visible" : "hidden"; }, 450);
  }
  const diffText = document.getElementById("diffText");
  diffText.hidden = mode !== "diff";
  if (mode === "diff") diffText.textContent = `${img.dataset.changedPixels || "…"} px changed`;
}

async function fillAgainst() {
  const sel = document.getElementById("compareAgainst");
  const scene = store.sceneId;
  try {
    const list = await fetchRevisions(api, scene);
    if (scene !== store.sceneId) return; // a late answer for the scene shown before
    sel.innerHTML = `<option value="off">patterns off</option>` +
      list.revisions.filter((r) => r.revision !== store.revision)
        .map((r) => `<option value="${r.revision}">r${r.revision} ${escapeHtml(r.op)}</option>`).join("");
    const keep = store.compare.against;
    const listed = [...sel.options].some((o) => o.value === keep);
    sel.value = listed ? keep : "off";
    // The menu and what the frame compares against stay one thing.
    if (!listed && keep !== "off") set({ compare: { ...store.compare, against: "off" } });
  } catch { /* the history panel shows errors */ }
}

const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

/// The pixel of the frame under a pointer event, or null outside the image.
function framePixel(e) {
  const r = img.getBoundingClientRect();
  const side = Math.min(r.width, r.height); // object-fit: contain, square frames
  const x0 = r.left + (r.width - side) / 2, y0 = r.top + (r.height - side) / 2;
  const x = ((e.clientX - x0) / side) * frameSize, y = ((e.clientY - y0) / side) * frameSize;
  if (x < 0 || y < 0 || x >= frameSize || y >= frameSize) return null;
  return [Math.floor(x), Math.floor(y)];
}

/// The side of the frame on screen in CSS pixels (object-fit: contain, square frames).
function displaySide() {
  const r = img.getBoundingClientRect();
  return Math.min(r.width, r.height) || frameSize;
}

/// The pick answer at a frame pixel of this view.
export function pickAt(x, y) {
  const p = frameParams();
  return api.get(pickPath(store.sceneId, { x, y, width: p.width, height: p.height, yaw: p.yaw,
                                           pitch: p.pitch, distance: p.distance, target: p.target, time: p.time }));
}

let clicks = 0; // clicks picked (see click)

/// A click on the frame: the pick there, then a new placement (place tool, Alt) or a selection.
/// A selection pick whose answer comes after a newer click, or after the selection changed some
/// other way meanwhile (the list, a key), is dropped: the newer choice stands.
async function click(e) {
  const px = framePixel(e);
  if (!px || !store.doc) return;
  const n = ++clicks, selection = store.selection;
  let hit;
  try { hit = await pickAt(px[0], px[1]); } catch (err) { notify(`Pick: ${err.message}`, "error"); return; }
  const current = n === clicks && store.selection === selection;
  if (!hit.hit) { if (!placeTool && !e.altKey && current) set({ selection: [] }); return; }
  if (placeTool || e.altKey) {
    emit(Topic.PLACE_AT, { uv: hit.uv, suggested: hit.suggested, anchor: hit.anchor });
    if (placeAs === "surface" && hit.anchor) await placeOnBody(hit.anchor, hit.suggested);
    else await placeAt(hit.uv, hit.suggested);
    return;
  }
  if (!current) return;
  const p = geo.hitPick(store.doc.placements, hit);
  if (p) set({ selection: [p.id] });
  else notify(`No placement at UV (${hit.uv[0].toFixed(3)}, ${hit.uv[1].toFixed(3)}); skin of ${hit.joints.map((j) => j.name).join(", ")}. Use the place tool (P) to add one here.`, "info");
}

/// The turntable of the selected placement (GET turntable: an animated WebP of its driver swept
/// θmin → θmax → θmin while the camera turns once about the current target) in a dialog, with a
/// link that downloads it.
export function openTurntable() {
  const pid = store.selection.find((id) => placementById(id));
  if (!pid) return notify("Select a placement first: the turntable shows its range of motion.", "warn");
  const c = store.camera;
  const url = turntableUrl(store.sceneId, { placement: pid, frames: 36, size: 320,
    yaw: c.yaw, pitch: c.pitch, distance: c.distance ?? undefined, target: c.target ? c.target.join(",") : undefined,
    time: shownTime(), revision: store.pinnedRevision ?? undefined, ...viewParams() });
  let dlg = document.getElementById("turntableDialog");
  if (!dlg) {
    dlg = document.createElement("dialog");
    dlg.id = "turntableDialog";
    dlg.setAttribute("aria-label", "turntable");
    document.body.appendChild(dlg);
  }
  const p = placementById(pid);
  dlg.innerHTML = `<h2>Turntable of ${escapeHtml(pid)}: ${escapeHtml(p.joint)} ${escapeHtml(String(p.axis))} ${p.theta_min}° → ${p.theta_max}° → ${p.theta_min}°</h2>
    <div class="turntable"><div class="spinner"></div><img alt="turntable of ${escapeHtml(pid)}" hidden></div>
    <form method="dialog"><a id="turntableDownload" href="${url}" download="turntable-${escapeHtml(pid)}.webp" title="Download the animated WebP">Download .webp</a> <button>Close</button></form>`;
  const image = dlg.querySelector("img");
  image.onload = () => { image.hidden = false; dlg.querySelector(".spinner").remove(); };
  image.onerror = () => { dlg.querySelector(".spinner")?.remove(); notify("The turntable could not be rendered.", "error"); };
  image.src = url;
  dlg.showModal();
}

let currentPattern = () => null;
let previewSource = () => null;
let ghostSource = () => null;
/// fn() → [x, y, z, nx, ny, nz, diameter]: a ghost outlined on the body as the surface brush's
/// dashed circle while the place tool is off (a proposal of the Propose… panel), or null.
export function setGhostSource(fn) { ghostSource = fn; }
function ghostBrush() {
  const g = ghostSource();
  return g ? g.map((x) => Math.round(x * 1e5) / 1e5).join(",") : undefined;
}
/// fn() → {placementId: fields} the frames preview (a drag in the texture view), or null.
export function setPreviewSource(fn) { previewSource = fn; }
export function setPatternSource(fn) { currentPattern = fn; }

/// Adds a surface placement of the library's current pattern at a pick's `anchor`, the brush's
/// diameter wide, driven by `suggested`.
export async function placeOnBody(anchor, suggested) {
  const pattern = currentPattern();
  if (!pattern) return notify("Choose a pattern in the library first.", "warn");
  const d = brushSize();
  if (!d) return notify("The 3D view has not shown a frame yet.", "warn");
  const body = applySuggested(surfacePlacementFromPattern(pattern, anchor, d), suggested, pattern);
  const answer = await addPlacement(body);
  if (answer) set({ selection: [answer.scene.placements[answer.scene.placements.length - 1].id] });
}

/// Adds a placement of the library's current pattern at `uv` driven by `suggested`.
export async function placeAt(uv, suggested) {
  const pattern = currentPattern();
  if (!pattern) return notify("Choose a pattern in the library first.", "warn");
  const body = applySuggested(placementFromPattern(pattern, uv), suggested, pattern);
  const answer = await addPlacement(body);
  if (answer) set({ selection: [answer.scene.placements[answer.scene.placements.length - 1].id] });
}

export { API };
