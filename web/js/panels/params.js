// Parameters panel of the primary selection: label, pattern, joint (searchable list of the model's
// joints), axis, θmin/θmax with the joint's current angle on a dial, h, model, target, response,
// footprint numbers; a plot of peak height (L = 1) against θ with the current θ and t marked;
// "go to pose" buttons (pose the driver at θmin / θmax) and the sweep contact sheet. Each field
// is sent when it changes (Enter or leaving it).

import { store, on, set, primary, placementById, shownTime, whenIdle, Topic } from "../store.js";
import { patchPlacement, patchPose, mirrorPlacement } from "../edits.js";
import { height, normalizedT } from "../deform.js";
import { escapeHtml } from "./library.js";
import { driversPath } from "../scene_resource.js";
import { openSweep } from "../sweep_view.js";
import { notify } from "../notice.js";
import { overrideAt, axisLabel } from "../joint_angles.js";

let api, box, drivers = new Map(), driversKey = "";

export function initParams(section, theApi) {
  api = theApi;
  section.innerHTML = `<h2>Parameters <span class="grow"></span><span id="paramsId" class="badge"></span></h2><div id="paramsBody"></div>`;
  box = section.querySelector("#paramsBody");
  on([Topic.SELECTION, Topic.MODEL, Topic.PATTERNS], render);
  on(Topic.DOC, () => refreshValues(false));
  // A refused edit: every field shows the document's value again, the one being typed in too.
  on(Topic.REFUSED, () => refreshValues(true));
  on([Topic.SELECTION, Topic.DOC, Topic.TIME, Topic.REVISION], () => whenIdle("drivers", loadDrivers, 60));
  on(Topic.DRIVERS, drawLive);
}

/// Each placement's current θ and t at the shown time (GET /scenes/{id}/drivers).
async function loadDrivers() {
  if (!store.sceneId || !store.doc) return;
  const key = `${store.sceneId}/${store.revision}/${shownTime()}`;
  if (key === driversKey) return;
  driversKey = key;
  try {
    const answer = await api.get(driversPath(store.sceneId, { time: shownTime(), revision: store.revision }));
    if (key !== driversKey) return;
    drivers = new Map(answer.placements.map((d) => [d.placement, d]));
    set({ liveCamera: answer.camera });
    drawLive();
  } catch (e) { if (key === driversKey) drivers = new Map(); } // an older read's failure leaves a newer read's answer
}
export const driverOf = (id) => drivers.get(id);

function field(label, html) { return `<label>${label}</label>${html}`; }
const opt = (values, cur) => values.map((v) => `<option${v === cur ? " selected" : ""}>${v}</option>`).join("");
/// x, y, z, and a vector axis (proposals, transfers, mirror twins) as itself, chosen.
const axisOptions = (axis) => (Array.isArray(axis) ? `<option value="vector" selected title="an axis in the joint's rest frame">${axisLabel(axis)}</option>` : "") + opt(["x", "y", "z"], axis);

function render() {
  const p = primary();
  shownId = p ? p.id : null;
  document.getElementById("paramsId").textContent = p ? p.id : "";
  if (!p) {
    box.innerHTML = `<p class="hint">Select a placement (click it in either view or in the list), or place a new one: choose a pattern and press 1–9 over the texture view, or use the place tool on the 3D view.</p>`;
    return;
  }
  const joints = store.model ? store.model.joints.map((j) => j.name) : [];
  const onBody = p.projection === "surface"; // a surface placement (SPEC §8): size and depth in model units
  box.innerHTML = `
    <div class="params">
      ${field("Label", `<input type="text" id="pLabel" maxlength="120" value="${escapeHtml(p.label || "")}" aria-label="label">`)}
      ${field("Pattern", `<select id="pPattern" aria-label="pattern">${store.patterns.map((q) => `<option value="${escapeHtml(q.id)}"${q.id === p.pattern ? " selected" : ""}>${escapeHtml(q.name || q.id)}</option>`).join("")}</select>`)}
      ${field("Joint", `<input type="search" id="pJoint" list="jointList" value="${escapeHtml(p.joint)}" aria-label="driver joint" autocomplete="off"><datalist id="jointList">${joints.map((j) => `<option value="${escapeHtml(j)}">`).join("")}</datalist>`)}
      ${field("Axis", `<select id="pAxis" aria-label="axis">${axisOptions(p.axis)}</select>`)}
      ${field("θ min / max", `<span class="pair"><input type="number" id="pMin" step="1" value="${p.theta_min}" aria-label="theta min"><input type="number" id="pMax" step="1" value="${p.theta_max}" aria-label="theta max"></span>`)}
      ${field("h", `<input type="number" id="pH" step="0.05" value="${p.h}" aria-label="h (gain)">`)}
      ${field("Model", `<select id="pModel" aria-label="deformation model">${opt(["scale", "bias"], p.model)}</select>`)}
      ${field("Target", `<select id="pTarget" aria-label="target map">${opt(["bump", "displacement"], p.target)}</select>`)}
      ${field("Response", `<select id="pResponse" aria-label="response">${opt(["log2", "ln", "linear", "smoothstep"], p.response)}</select>`)}
      ${onBody ? field("Size", `<span class="pair"><input type="number" id="pSX" step="any" min="0" value="${p.size[0]}" aria-label="width (model units)" title="width along the tangent, model units"><input type="number" id="pSY" step="any" min="0" value="${p.size[1]}" aria-label="height (model units)" title="height, model units"></span>`)
                 + field("Depth", `<input type="number" id="pDepth" step="any" min="0" value="${typeof p.depth === "number" ? p.depth : ""}" placeholder="auto" aria-label="depth (model units; empty: auto)" title="how far from the anchor's tangent plane the decal reaches, model units (empty: auto = half the larger size)">`)
               : field("Centre", `<span class="pair"><input type="number" id="pU" step="0.001" value="${p.center[0]}" aria-label="centre u"><input type="number" id="pV" step="0.001" value="${p.center[1]}" aria-label="centre v"></span>`)
                 + field("Scale", `<span class="pair"><input type="number" id="pSX" step="0.005" value="${p.scale[0]}" aria-label="scale u"><input type="number" id="pSY" step="0.005" value="${p.scale[1]}" aria-label="scale v"></span>`)}
      ${field("Rotation", `<input type="number" id="pRot" step="1" value="${p.rotation}" aria-label="rotation (degrees)">`)}
      ${field("Enabled", `<input type="checkbox" id="pEnabled"${p.enabled ? " checked" : ""} aria-label="enabled">`)}
      <div class="wide live"><canvas class="dial" id="dial" width="176" height="176" aria-label="current joint angle"></canvas>
        <div class="buttons"><div id="liveText" aria-live="polite"></div>
          <button type="button" id="goMin" title="Pose the driver joint at θmin">Go to θmin</button><button type="button" id="goMax" title="Pose the driver joint at θmax">Go to θmax</button>
          <button type="button" id="clearPose" title="Remove this joint's pose override">Release joint</button><button type="button" id="sweep" title="Contact sheet of the driver's range">Sweep…</button>
          <button type="button" id="mirror" title="Add the mirror twin (M)">Mirror</button>
        </div></div>
      <canvas class="plot wide" id="plot" width="520" height="240" aria-label="height against theta"></canvas>
    </div>`;
  const $ = (id) => box.querySelector("#" + id);
  const send = (fields) => patchPlacement(p.id, fields);
  const cur = () => placementById(p.id) || p; // the buttons act on the placement as it is now
  const num = (el) => { const v = +el.value; return Number.isFinite(v) && el.value !== "" ? v : null; };
  $("pLabel").onchange = (e) => send({ label: e.target.value });
  $("pPattern").onchange = (e) => send({ pattern: e.target.value });
  $("pJoint").onchange = (e) => {
    if (!joints.includes(e.target.value)) { notify(`The model has no joint named "${e.target.value}".`, "error"); e.target.value = cur().joint; return; }
    send({ joint: e.target.value });
  };
  $("pAxis").onchange = (e) => { if (e.target.value !== "vector") send({ axis: e.target.value }); };
  for (const [id, key] of [["pMin", "theta_min"], ["pMax", "theta_max"], ["pH", "h"], ["pRot", "rotation"]])
    $(id).onchange = (e) => { const v = num(e.target); if (v !== null) send({ [key]: v }); };
  $("pModel").onchange = (e) => send({ model: e.target.value });
  $("pTarget").onchange = (e) => send({ target: e.target.value });
  $("pResponse").onchange = (e) => send({ response: e.target.value });
  $("pEnabled").onchange = (e) => send({ enabled: e.target.checked });
  const pairSend = (a, b, key) => () => { const x = num($(a)), y = num($(b)); if (x !== null && y !== null) send({ [key]: [x, y] }); };
  if (onBody) {
    $("pSX").onchange = $("pSY").onchange = pairSend("pSX", "pSY", "size");
    $("pDepth").onchange = (e) => { const v = num(e.target); send({ depth: e.target.value === "" ? "auto" : v }); };
  } else {
    $("pU").onchange = $("pV").onchange = pairSend("pU", "pV", "center");
    $("pSX").onchange = $("pSY").onchange = pairSend("pSX", "pSY", "scale");
  }
  $("goMin").onclick = () => goToPose(cur(), cur().theta_min);
  $("goMax").onclick = () => goToPose(cur(), cur().theta_max);
  $("clearPose").onclick = () => patchPose({ joints: { [cur().joint]: null } });
  $("sweep").onclick = () => openSweep(cur());
  $("mirror").onclick = () => mirrorPlacement(p.id);
  drawLive();
}

let shownId = null;

/// The document changed: the same placement's fields take the new values in place (the field
/// being typed in keeps its text unless `all`); another placement, or a vanished one, renders anew.
function refreshValues(all) {
  const p = primary();
  const onBody = p && p.projection === "surface";
  if (!p || p.id !== shownId || !box.querySelector("#pH") || onBody !== !!box.querySelector("#pDepth")) { render(); return; }
  const set = (id, v) => { const el = box.querySelector("#" + id); if (el && (all || el !== document.activeElement)) el.value = String(v); };
  set("pLabel", p.label || ""); set("pPattern", p.pattern); set("pJoint", p.joint); set("pAxis", Array.isArray(p.axis) ? "vector" : p.axis);
  set("pMin", p.theta_min); set("pMax", p.theta_max); set("pH", p.h); set("pModel", p.model); set("pTarget", p.target);
  set("pResponse", p.response);
  if (onBody) { set("pSX", p.size[0]); set("pSY", p.size[1]); set("pDepth", typeof p.depth === "number" ? p.depth : ""); }
  else { set("pU", p.center[0]); set("pV", p.center[1]); set("pSX", p.scale[0]); set("pSY", p.scale[1]); }
  set("pRot", p.rotation);
  const en = box.querySelector("#pEnabled");
  if (en) en.checked = p.enabled;
  drawLive();
}

/// Poses the placement's driver joint at `theta` about its axis (other letter axes of that joint
/// kept; about a vector axis the joint's rotation is set: joint_angles.js).
export function goToPose(p, theta) {
  const cur = (store.doc.pose.joints || {})[p.joint];
  return patchPose({ joints: { [p.joint]: overrideAt(p.joint, p.axis, theta, cur) } });
}

/// The current θ and t of placement p: from the server's drivers answer when it has one.
function live(p) {
  const d = drivers.get(p.id);
  if (d) return { theta: d.theta, t: d.t };
  return { theta: null, t: null };
}

function drawLive() {
  const p = primary();
  if (!p || !box.querySelector("#plot")) return;
  const { theta, t } = live(p);
  box.querySelector("#liveText").textContent = theta === null ? "θ —" :
    `θ = ${theta.toFixed(1)}°  t = ${t.toFixed(3)}  height = ${height(p, 1, t).toFixed(3)}`;
  drawDial(box.querySelector("#dial"), p, theta);
  drawPlot(box.querySelector("#plot"), p, theta);
}

function drawDial(c, p, theta) {
  const g = c.getContext("2d"), w = c.width, r = w * 0.42, cx = w / 2, cy = w / 2;
  g.clearRect(0, 0, w, w);
  const ang = (deg) => ((deg - 90) * Math.PI) / 180; // 0° up, clockwise positive
  g.lineWidth = 10;
  g.strokeStyle = "#2a323d";
  g.beginPath(); g.arc(cx, cy, r, 0, Math.PI * 2); g.stroke();
  const lo = Math.min(p.theta_min, p.theta_max), hi = Math.max(p.theta_min, p.theta_max);
  g.strokeStyle = "#2d6fa8";
  g.beginPath(); g.arc(cx, cy, r, ang(lo), ang(hi)); g.stroke();
  g.lineWidth = 2;
  for (const [deg, col] of [[p.theta_min, "#8d99a8"], [p.theta_max, "#5fb3ff"]]) {
    g.strokeStyle = col;
    g.beginPath(); g.moveTo(cx, cy); g.lineTo(cx + Math.cos(ang(deg)) * (r + 6), cy + Math.sin(ang(deg)) * (r + 6)); g.stroke();
  }
  if (theta !== null) {
    g.strokeStyle = "#ffb454";
    g.lineWidth = 4;
    g.beginPath(); g.moveTo(cx, cy); g.lineTo(cx + Math.cos(ang(theta)) * r, cy + Math.sin(ang(theta)) * r); g.stroke();
  }
  g.fillStyle = "#dde3ea";
  g.font = "bold 22px system-ui, sans-serif";
  g.textAlign = "center";
  g.fillText(theta === null ? "—" : `${theta.toFixed(0)}°`, cx, cy + 8);
}

function drawPlot(c, p, theta) {
  const g = c.getContext("2d"), W = c.width, H = c.height, pad = 28;
  g.clearRect(0, 0, W, H);
  const span = Math.abs(p.theta_max - p.theta_min) || 1;
  const a = Math.min(p.theta_min, p.theta_max) - span * 0.25, b = Math.max(p.theta_min, p.theta_max) + span * 0.25;
  const top = Math.max(Math.abs(p.h), 1e-6);
  const X = (th) => pad + ((th - a) / (b - a)) * (W - 2 * pad);
  const Y = (v) => H - pad - (v / top) * (H - 2 * pad) * (p.h < 0 ? -1 : 1);
  g.strokeStyle = "#343c48";
  g.lineWidth = 1;
  g.beginPath(); g.moveTo(pad, H - pad); g.lineTo(W - pad, H - pad); g.moveTo(pad, pad); g.lineTo(pad, H - pad); g.stroke();
  g.fillStyle = "#8d99a8";
  g.font = "18px system-ui, sans-serif";
  g.fillText(`θ ${a.toFixed(0)}°…${b.toFixed(0)}°`, pad + 4, H - 6);
  g.fillText(`height (L = 1), h = ${p.h}`, pad + 4, pad - 8);
  g.strokeStyle = "#5fb3ff";
  g.lineWidth = 3;
  g.beginPath();
  for (let i = 0; i <= 200; ++i) {
    const th = a + ((b - a) * i) / 200;
    const v = height(p, 1, normalizedT(th, p.theta_min, p.theta_max));
    i ? g.lineTo(X(th), Y(v)) : g.moveTo(X(th), Y(v));
  }
  g.stroke();
  c.dataset.curve = [0, 0.25, 0.5, 0.75, 1].map((f) => height(p, 1, f).toFixed(4)).join(",");
  if (theta !== null) {
    const t = normalizedT(theta, p.theta_min, p.theta_max);
    g.fillStyle = "#ffb454";
    g.beginPath(); g.arc(X(Math.min(Math.max(theta, a), b)), Y(height(p, 1, t)), 6, 0, Math.PI * 2); g.fill();
  }
}

/// The sweep contact sheet of p's driver range in a dialog (sweep_view.js: the 3D view's camera).
export { openSweep };
