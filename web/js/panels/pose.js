// Pose and playback bar: the clip (the scene's pose.animation), play/pause, the time scrubber (the
// shown time: it changes frames, not the document), and a slider per joint axis that drives a
// placement (pose.joints overrides: dragging sends coalesced pose edits; "release" removes one).

import { store, on, set, clipByName, shownTime, Topic } from "../store.js";
import { patchPose, Stream } from "../edits.js";
import { escapeHtml } from "./library.js";
import { overrideAngle, overrideAt, axisLabel } from "../joint_angles.js";

let clipSel, playBtn, slider, timeText, jointsBox, playing = false, last = 0;

export function initPose(section) {
  section.innerHTML = `
    <div class="row">
      <label>Clip <select id="clip" aria-label="clip"></select></label>
      <button type="button" id="play" aria-label="play" title="Play / pause (Space)">▶</button>
      <input id="time" type="range" min="0" max="1" step="0.01" value="0" aria-label="time">
      <span id="timeText" class="badge">0.00 s</span>
      <button type="button" id="setTime" title="Store the shown time as the scene's pose time">Set pose time</button>
    </div>
    <div class="joints" id="jointSliders" aria-label="driver joints"></div>`;
  clipSel = section.querySelector("#clip");
  playBtn = section.querySelector("#play");
  slider = section.querySelector("#time");
  timeText = section.querySelector("#timeText");
  jointsBox = section.querySelector("#jointSliders");
  clipSel.onchange = () => { set({ time: 0 }); patchPose({ animation: clipSel.value || null, time: 0 }); };
  playBtn.onclick = () => togglePlay();
  slider.oninput = () => set({ time: +slider.value });
  section.querySelector("#setTime").onclick = () => patchPose({ time: shownTime() });
  on([Topic.DOC, Topic.MODEL], renderClips);
  on(Topic.DOC, renderJoints);
  on([Topic.TIME, Topic.DOC], showTime);
}

function renderClips() {
  if (!store.model || !store.doc) return;
  const cur = store.doc.pose.animation || "";
  clipSel.innerHTML = `<option value="">(no clip)</option>` +
    store.model.clips.map((c) => `<option value="${escapeHtml(c.name)}"${c.name === cur ? " selected" : ""}>${escapeHtml(c.name)} (${c.duration.toFixed(1)} s)</option>`).join("");
  const clip = clipByName(cur);
  slider.max = clip ? String(clip.duration) : "1";
  slider.disabled = !clip;
}

function showTime() {
  const t = shownTime();
  if (document.activeElement !== slider) slider.value = String(t);
  timeText.textContent = `${t.toFixed(2)} s`;
}

export function togglePlay() {
  const clip = store.doc && clipByName(store.doc.pose.animation);
  if (!clip) return;
  playing = !playing;
  playBtn.textContent = playing ? "❚❚" : "▶";
  playBtn.setAttribute("aria-label", playing ? "pause" : "play");
  last = performance.now();
  if (playing) requestAnimationFrame(tick);
}

function tick(now) {
  if (!playing) return;
  const clip = store.doc && clipByName(store.doc.pose.animation);
  if (!clip) { togglePlay(); return; }
  const dt = (now - last) / 1000;
  last = now;
  let t = shownTime() + dt;
  if (t > clip.duration) t = 0;
  set({ time: Math.round(t * 100) / 100 });
  requestAnimationFrame(tick);
}

/// The joint axes that drive placements (unique), with the pose override's value if any.
function drivers() {
  const seen = new Map();
  for (const p of store.doc.placements) {
    const key = `${p.joint}/${p.axis}`;
    if (!seen.has(key)) seen.set(key, { joint: p.joint, axis: p.axis, lo: Math.min(p.theta_min, p.theta_max), hi: Math.max(p.theta_min, p.theta_max) });
    else { const d = seen.get(key); d.lo = Math.min(d.lo, p.theta_min, p.theta_max); d.hi = Math.max(d.hi, p.theta_min, p.theta_max); }
  }
  return [...seen.values()];
}

let jointStream = null;

function renderJoints() {
  if (!store.doc || jointStream) return; // a slider being dragged keeps its DOM
  const overrides = store.doc.pose.joints || {};
  jointsBox.innerHTML = "";
  for (const d of drivers()) {
    const cur = overrideAngle(overrides[d.joint], d.joint, d.axis);
    const axisName = axisLabel(d.axis), axisKey = Array.isArray(d.axis) ? d.axis.join(",") : d.axis;
    const span = Math.max(d.hi - d.lo, 10);
    const lo = Math.max(-180, Math.floor(d.lo - span * 0.25)), hi = Math.min(180, Math.ceil(d.hi + span * 0.25));
    const label = document.createElement("label");
    label.innerHTML = `${escapeHtml(d.joint)} ${escapeHtml(axisName)}
      <input type="range" min="${lo}" max="${hi}" step="0.5" value="${cur ?? 0}" aria-label="${escapeHtml(d.joint)} ${escapeHtml(axisName)} angle" data-joint="${escapeHtml(d.joint)}" data-axis="${escapeHtml(axisKey)}">
      <span class="badge">${cur === undefined ? "anim" : cur.toFixed(1) + "°"}</span>`;
    const input = label.querySelector("input"), badge = label.querySelector(".badge");
    input.oninput = () => {
      if (!jointStream) jointStream = new Stream((v) => patchPose(v, { undoable: false }), { live: true, what: `pose ${d.joint} ${axisName}` });
      badge.textContent = `${(+input.value).toFixed(1)}°`;
      jointStream.send({ joints: { [d.joint]: overrideAt(d.joint, d.axis, +input.value, overrides[d.joint]) } });
    };
    input.onchange = async () => {
      const s = jointStream;
      if (!s) return;
      await s.finish();
      jointStream = null;
      renderJoints();
    };
    jointsBox.append(label);
  }
}
