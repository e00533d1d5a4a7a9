// The sweep contact sheet (GET sweep) of a placement in a dialog, seen with the 3D view's camera
// (yaw, pitch, distance, target), or zoomed on the placement's skin ("Zoom to placement": the
// camera target and distance of GET focus, larger cells) so that a crease is big enough to see;
// or of a clip (GET sweep?clip=: its time from 0 to its duration, each cell labelled with the t of
// the placements most active then) — every pattern of a scene at work at once.

import { store, shownTime } from "./store.js";
import { sweepUrl as sweepRouteUrl } from "./scene_resource.js";
import { notify } from "./notice.js";
import { focusOf } from "./camera3d.js";

const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

/// The sheet's URL: the view's camera, or with `zoom` the placement's region (focus answer).
export function sweepUrl(p, zoom = null) {
  const c = store.camera;
  const camera = zoom ? { distance: zoom.distance, target: zoom.target.join(",") }
                      : { distance: c.distance ?? undefined, target: c.target ? c.target.join(",") : undefined };
  return sweepRouteUrl(store.sceneId, { placement: p.id, steps: zoom ? 6 : 8, size: zoom ? 256 : 192,
    yaw: c.yaw, pitch: c.pitch, ...camera, time: shownTime(), revision: store.pinnedRevision ?? undefined });
}

/// Opens the sweep dialog of placement p.
export async function openSweep(p) {
  const dlg = document.getElementById("sweepDialog");
  dlg.innerHTML = `<h2>Sweep of ${escapeHtml(p.id)}: ${escapeHtml(p.joint)} ${escapeHtml(String(p.axis))} from ${p.theta_min}° to ${p.theta_max}°</h2>
    <label class="sweepzoom"><input type="checkbox" id="sweepZoom"> Zoom to placement</label>
    <div><img id="sweepSheet" alt="sweep contact sheet of ${escapeHtml(p.id)}" src="${sweepUrl(p)}"></div><form method="dialog"><button>Close</button></form>`;
  const image = dlg.querySelector("img");
  image.onerror = () => notify("The sweep could not be rendered.", "error");
  dlg.querySelector("#sweepZoom").onchange = async (e) => {
    try {
      const zoom = e.target.checked ? await focusOf(p.id, { time: shownTime(), revision: store.pinnedRevision ?? store.revision }) : null;
      image.src = sweepUrl(p, zoom);
    } catch (err) { notify(`Sweep: ${err.message}`, "error"); e.target.checked = false; }
  };
  dlg.showModal();
}

/// Opens the sweep dialog of clip `clip` (6 cells of the clip's time, the 3D view's camera).
export function openClipSweep(clip) {
  const c = store.camera;
  const url = sweepRouteUrl(store.sceneId, { clip, steps: 6, size: 352, yaw: c.yaw, pitch: c.pitch,
    distance: c.distance ?? undefined, target: c.target ? c.target.join(",") : undefined, revision: store.pinnedRevision ?? undefined });
  const dlg = document.getElementById("sweepDialog");
  dlg.innerHTML = `<h2>Sweep of the clip ${escapeHtml(clip)}: every placement over its time</h2>
    <div><img id="sweepSheet" alt="sweep contact sheet of the clip ${escapeHtml(clip)}" src="${url}"></div><form method="dialog"><button>Close</button></form>`;
  dlg.querySelector("img").onerror = () => notify("The sweep could not be rendered.", "error");
  dlg.showModal();
}
