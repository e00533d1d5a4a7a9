// Permalink: the address bar names the scene, revision, time, camera, view, frame size and
// selection (?scene=…&revision=…&time=…&yaw=…&pitch=…&distance=…&target=x,y,z&view=…&size=…&sel=a,b).
// Opening such a link shows that revision's frame from that camera at that time — the same
// frame request, so the same bytes on the same server — until the person edits or leaves it.

import { store, on, set, Topic } from "./store.js";
import { frameSize } from "./frame_view.js";

/// What the page's URL asks for (numbers parsed; absent fields undefined).
export function readLink() {
  const q = new URLSearchParams(location.search);
  const num = (k) => (q.has(k) && q.get(k) !== "" && Number.isFinite(+q.get(k)) ? +q.get(k) : undefined);
  return {
    scene: q.get("scene") || undefined,
    revision: num("revision"),
    time: num("time"),
    yaw: num("yaw"), pitch: num("pitch"), distance: num("distance"),
    target: q.get("target") && q.get("target").split(",").length === 3 && q.get("target").split(",").every((x) => x !== "" && Number.isFinite(+x))
      ? q.get("target").split(",").map(Number) : undefined,
    view: q.get("view") || undefined,
    size: num("size"),
    selection: q.get("sel") ? q.get("sel").split(",").filter(Boolean) : undefined,
  };
}

/// The link of what is shown now.
export function currentLink() {
  const q = new URLSearchParams();
  q.set("scene", store.sceneId);
  q.set("revision", String(store.pinnedRevision ?? store.revision));
  const t = store.time !== null ? store.time : store.doc ? store.doc.pose.time || 0 : 0;
  q.set("time", String(Math.round(t * 1e4) / 1e4));
  q.set("yaw", String(store.camera.yaw));
  q.set("pitch", String(store.camera.pitch));
  if (store.camera.distance !== null) q.set("distance", String(store.camera.distance));
  if (store.camera.target) q.set("target", store.camera.target.join(","));
  if (store.view !== "shaded") q.set("view", store.view);
  q.set("size", String(frameSize));
  if (store.selection.length) q.set("sel", store.selection.join(","));
  return `${location.origin}${location.pathname}?${q}`;
}

export function initPermalink() {
  let timer = null;
  on([Topic.DOC, Topic.REVISION, Topic.TIME, Topic.CAMERA, Topic.VIEW, Topic.SELECTION, Topic.PINNED_REVISION], () => {
    clearTimeout(timer);
    timer = setTimeout(() => { if (store.sceneId) history.replaceState(null, "", currentLink()); }, 150);
  });
}

/// Copies the link to the clipboard (falls back to a prompt where the clipboard is refused).
export async function copyLink() {
  const link = currentLink();
  history.replaceState(null, "", link);
  try {
    await navigator.clipboard.writeText(link);
    return true;
  } catch {
    window.prompt("Copy this link:", link);
    return false;
  }
}

export { set };
