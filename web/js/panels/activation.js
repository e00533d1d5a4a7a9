// Activation strip: t of each placement over the current clip (GET /scenes/{id}/activation), one
// lane per placement (brightness = t), the route's flags marked (never active, saturated, jump),
// the shown time as a cursor; click or drag to jump to a time.

import { store, on, set, clipByName, shownTime, whenIdle, Topic } from "../store.js";
import { activationPath } from "../scene_resource.js";
import { notify } from "../notice.js";

let api, canvas, data = null, key = "";

export function initActivation(section, theApi) {
  api = theApi;
  section.innerHTML = `<canvas id="activation" width="900" height="220" tabindex="0" aria-label="activation strip: t of each placement over the clip; click to jump to a time"></canvas>`;
  canvas = section.querySelector("#activation");
  on([Topic.REVISION, Topic.DOC], () => whenIdle("activation", load));
  on([Topic.TIME, Topic.SELECTION], draw);
  const jump = (e) => {
    if (!data) return;
    const r = canvas.getBoundingClientRect();
    const f = (e.clientX - r.left - labelW(r.width)) / (r.width - labelW(r.width));
    const clip = clipByName(data.clip);
    if (clip) set({ time: Math.round(Math.min(Math.max(f, 0), 1) * clip.duration * 100) / 100 });
  };
  canvas.addEventListener("pointerdown", (e) => { jump(e); canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointermove", (e) => { if (e.buttons) jump(e); });
  canvas.addEventListener("keydown", (e) => {
    const clip = data && clipByName(data.clip);
    if (!clip || (e.key !== "ArrowLeft" && e.key !== "ArrowRight")) return;
    e.preventDefault();
    e.stopPropagation();
    const step = e.key === "ArrowLeft" ? -1 / 30 : 1 / 30;
    set({ time: Math.round(Math.min(Math.max(shownTime() + step, 0), clip.duration) * 100) / 100 });
  });
  new ResizeObserver(draw).observe(canvas);
}

const labelW = (w) => Math.min(110, w * 0.18);

async function load() {
  const clip = store.doc && store.doc.pose.animation;
  const k = `${store.sceneId}/${store.revision}/${clip}`;
  if (k === key) return;
  key = k;
  if (!clip) { data = null; draw(); return; }
  try {
    const answer = await api.get(activationPath(store.sceneId, clip, 30));
    if (k !== key) return;
    data = answer;
  } catch (e) {
    if (k !== key) return; // an older read's failure: a newer read owns the curves
    data = null;
    notify(`Activation: ${e.message}`, "error");
  }
  draw();
}

function draw() {
  const dpr = window.devicePixelRatio || 1;
  const W = canvas.clientWidth || 600, H = canvas.clientHeight || 110;
  canvas.width = Math.round(W * dpr);
  canvas.height = Math.round(H * dpr);
  const g = canvas.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.fillStyle = "#0d1014";
  g.fillRect(0, 0, W, H);
  g.font = "10px system-ui, sans-serif";
  if (!data || !store.doc) {
    g.fillStyle = "#8d99a8";
    g.fillText("Choose a clip to see when each placement activates.", 10, 20);
    return;
  }
  const ids = store.doc.placements.map((p) => p.id).filter((id) => data.placements[id]);
  // Lanes are named as the placements list names them: the label, else the id.
  const nameOf = (id) => { const p = store.doc.placements.find((q) => q.id === id); return (p && p.label) || id; };
  canvas.dataset.lanes = JSON.stringify(ids.map(nameOf));
  // Lanes of 12 px (labels readable at 11 px): the strip grows with the placements up to 200 px,
  // then lanes shrink. Setting the height redraws through the ResizeObserver.
  const wantH = Math.round(Math.min(200, Math.max(110, 12 + ids.length * 12)));
  if (Math.abs(wantH - H) > 1) { canvas.style.height = `${wantH}px`; return; }
  const lw = labelW(W), lane = Math.max(3, (H - 12) / Math.max(ids.length, 1));
  const n = data.times.length;
  const X = (i) => lw + (i / Math.max(n - 1, 1)) * (W - lw);
  ids.forEach((id, row) => {
    const y = 2 + row * lane;
    const ts = data.placements[id];
    const selected = store.selection.includes(id);
    for (let i = 0; i < n; ++i) {
      const t = ts[i];
      g.fillStyle = `rgba(${selected ? "255,180,84" : "95,179,255"},${0.08 + 0.92 * t})`;
      g.fillRect(X(i), y, (W - lw) / n + 1, lane - 1);
    }
    if (lane >= 6) {
      g.font = `${Math.min(11, Math.floor(lane - 1))}px system-ui, sans-serif`;
      g.fillStyle = selected ? "#ffb454" : "#b8c2cf";
      g.textBaseline = "middle";
      g.fillText(nameOf(id), 4, y + (lane - 1) / 2, lw - 10);
      g.textBaseline = "alphabetic";
    }
  });
  for (const f of data.flags) {
    const row = ids.indexOf(f.placement);
    if (row < 0) continue;
    const y = 2 + row * lane;
    g.fillStyle = f.kind === "jump" ? "#ff6b6b" : f.kind === "saturated" ? "#ffb454" : "#8d99a8";
    if (f.at === null || f.at === undefined) { g.fillRect(lw - 6, y, 4, lane - 1); continue; }
    const clip = clipByName(data.clip);
    const x = lw + (f.at / (clip ? clip.duration : 1)) * (W - lw);
    g.beginPath(); g.moveTo(x, y); g.lineTo(x + 4, y + lane / 2); g.lineTo(x, y + lane - 1); g.lineTo(x - 4, y + lane / 2); g.fill();
  }
  const clip = clipByName(data.clip);
  if (clip) {
    const x = lw + (shownTime() / clip.duration) * (W - lw);
    g.fillStyle = "#ffffff";
    g.fillRect(x - 1, 0, 2, H);
  }
  canvas.title = data.flags.map((f) => `${nameOf(f.placement)}: ${f.kind.replace("_", " ")}${f.at != null ? ` at ${(+f.at).toFixed(2)} s` : ""}`).join("\n");
}
