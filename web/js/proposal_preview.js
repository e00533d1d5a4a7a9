// The preview of one proposed pattern (the Propose… panel): the proposal alone on the body at its
// neutral and at its peak angle, zoomed on where it shows. The scene does not have the proposal
// yet, so the frame route (whose `preview` only patches placements the scene has) cannot show it:
// the stateless batch route does (POST /render with the scene's document holding that one
// placement). Three small batches, ~0.1 s each on llvmpipe:
//   1. the height view (bump, or displacement for a bulge) at the peak pose from the 3D view's
//      camera and from behind — the pattern is the only grey off 128 on the body, so its pixels say
//      which side shows it and where (the frame's own pixels: no skinning in the page);
//   2. the shaded frames at θmin (neutral) and θmax (peak) from that side, cropped about it.
// The peak pose is the clip where the joint bends most at its peak time (why.peak_clip/peak_time),
// with the driver joint set to θ about the placement's axis (joint_angles.js: the angle the server
// measures, SPEC §2), or the scene's pose where the range is synthetic (no clip).

import { store } from "./store.js";
import { overrideAt } from "./joint_angles.js";

const SIZE = 896;  // side of the rendered frames
const CELL = 128;  // side of a cell of the preview canvas

/// The pose of `doc` at which `placement`'s driver is at `theta` (degrees): the clip and time of
/// `why` (or the document's pose) with the driver joint's rotation set (joint_angles.js).
export function poseAt(placement, why, theta, doc = store.doc) {
  const base = why && why.peak_clip && !why.synthetic ? { animation: why.peak_clip, time: why.peak_time || 0 } : { ...doc.pose };
  const joints = { ...(base.joints || {}) };
  joints[placement.joint] = overrideAt(placement.joint, placement.axis, theta, joints[placement.joint]);
  return { ...base, joints };
}

/// The scene's document with `placement` alone, seen from `yaw` (the 3D view's pitch and distance).
function docWith(placement, yaw) {
  const c = store.camera;
  const render = { ...store.doc.render, size: [SIZE, SIZE], msaa: 1,
                   camera: { yaw: ((yaw % 360) + 360) % 360, pitch: c.pitch ?? 10, distance: c.distance ?? "auto" } };
  return { ...store.doc, placements: [{ ...placement, enabled: true }], render };
}

/// The frames of a batch (POST /render) as ImageBitmaps, in order.
async function batch(api, scene, frames, view, signal) {
  const r = await api.raw("POST", "/render", { body: { scene, frames, format: "png", ...(view ? { view } : {}) }, signal });
  const boundary = /boundary=([^;]+)/.exec(r.headers.get("Content-Type") || "");
  const bytes = new Uint8Array(await r.arrayBuffer());
  const parts = multipart(bytes, boundary ? boundary[1].trim() : "dermis-frame-boundary");
  return Promise.all(parts.map((p) => createImageBitmap(new Blob([p], { type: "image/png" }))));
}

/// The bodies of a multipart/mixed answer, by frame order (X-Dermis-Frame) where given.
export function multipart(bytes, boundary) {
  const text = new TextDecoder("latin1").decode(bytes); // one char per byte: offsets match
  const out = [];
  let at = text.indexOf(`--${boundary}`);
  while (at >= 0) {
    const head = text.indexOf("\r\n\r\n", at);
    if (head < 0) break;
    const headers = text.slice(at, head);
    const length = /Content-Length:\s*(\d+)/i.exec(headers);
    const frame = /X-Dermis-Frame:\s*(\d+)/i.exec(headers);
    const start = head + 4;
    const end = length ? start + +length[1] : text.indexOf(`\r\n--${boundary}`, start);
    if (end < start) break;
    out.push({ index: frame ? +frame[1] : out.length, body: bytes.subarray(start, end) });
    at = text.indexOf(`--${boundary}`, end);
  }
  return out.sort((a, b) => a.index - b.index).map((p) => p.body);
}

/// The box [x0, y0, x1, y1] and count of the pixels of a height-view frame where the pattern
/// shows: grey (r = g = b, the body) off the flat 128 (the background is not grey).
function patternPixels(bitmap) {
  const c = new OffscreenCanvas(bitmap.width, bitmap.height);
  const g = c.getContext("2d");
  g.drawImage(bitmap, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let n = 0, x0 = Infinity, y0 = Infinity, x1 = -1, y1 = -1;
  for (let i = 0, k = 0; i < d.length; i += 4, ++k) {
    if (d[i] !== d[i + 1] || d[i] !== d[i + 2] || Math.abs(d[i] - 128) <= 2) continue;
    const x = k % c.width, y = (k / c.width) | 0;
    ++n; x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
  }
  return { n, box: n ? [x0, y0, x1 + 1, y1 + 1] : null };
}

/// Renders the preview of proposal `prop` ({placement, why}) into `canvas` (3 cells: where on the
/// body, neutral, peak). Resolves to {side, pixels} (the yaw shown, the pattern's pixels there);
/// rejects with an AbortError when `signal` aborts.
export async function renderProposalPreview(api, prop, canvas, signal) {
  const p = prop.placement, why = prop.why || {};
  const peak = poseAt(p, why, p.theta_max), rest = poseAt(p, why, p.theta_min);
  const view = p.target === "displacement" ? "displacement" : "bump";
  const yaw = store.camera.yaw ?? 0;
  const sides = [yaw, yaw + 180];
  const heights = await Promise.all(sides.map((y) => batch(api, docWith(p, y), [{ pose: peak }], view, signal).then((b) => b[0])));
  const found = heights.map(patternPixels);
  const best = found[1].n > found[0].n ? 1 : 0;
  const [neutral, peaked] = await batch(api, docWith(p, sides[best]), [{ pose: rest }, { pose: peak }], null, signal);
  const box = found[best].box;
  // A square about the pattern (2.5 times its extent, at least a seventh of the frame).
  const [cx, cy] = box ? [(box[0] + box[2]) / 2, (box[1] + box[3]) / 2] : [SIZE / 2, SIZE / 2];
  const side = box ? Math.min(SIZE, Math.max(SIZE / 7, 2.5 * Math.max(box[2] - box[0], box[3] - box[1]))) : SIZE;
  const sx = Math.min(Math.max(cx - side / 2, 0), SIZE - side), sy = Math.min(Math.max(cy - side / 2, 0), SIZE - side);
  canvas.width = 3 * CELL + 8;
  canvas.height = CELL + 16;
  const g = canvas.getContext("2d");
  g.fillStyle = "#0d1014";
  g.fillRect(0, 0, canvas.width, canvas.height);
  g.drawImage(heights[best], 0, 0, SIZE, SIZE, 0, 0, CELL, CELL);
  if (box) {
    g.strokeStyle = "#5fb3ff";
    g.lineWidth = 1.5;
    g.strokeRect(sx / SIZE * CELL, sy / SIZE * CELL, side / SIZE * CELL, side / SIZE * CELL);
  }
  g.imageSmoothingQuality = "high";
  g.drawImage(neutral, sx, sy, side, side, CELL + 4, 0, CELL, CELL);
  g.drawImage(peaked, sx, sy, side, side, 2 * CELL + 8, 0, CELL, CELL);
  g.fillStyle = "#8d99a8";
  g.font = "11px system-ui, sans-serif";
  const deg = (x) => `${Math.round(x * 10) / 10}°`;
  g.fillText(box ? (best ? "from behind" : "from the front") : "not in sight", 2, CELL + 12);
  g.fillText(`θ ${deg(p.theta_min)} (neutral)`, CELL + 6, CELL + 12);
  g.fillText(`θ ${deg(p.theta_max)} (peak)`, 2 * CELL + 10, CELL + 12);
  return { side: ((sides[best] % 360) + 360) % 360, pixels: found[best].n };
}
