// Dermis editor entry: builds the API client, the views and the panels, loads the scene the URL
// (or the first scene) names, and wires the toolbar: scene switch, undo/redo, layout, new scene
// from a dropped or chosen .glb, download / load of the scene document, "Propose…" (the pattern
// set the server proposes for the character), "Transfer from…" (another scene's placements carried
// onto this character), and "Copy link".

import { Api, makeClientName, ApiError } from "./api.js";
import { store, set, on, emit, whenIdle, placementById, Topic } from "./store.js";
import { SCENES_PATH, scenePath, lintPath, heightmapsPath } from "./scene_resource.js";
import { signIn } from "./signin.js";
import { notify } from "./notice.js";
import { initImages, forget } from "./images.js";
import { initEdits, accept, clearUndo, canUndo, canRedo, putScene, undo, redo, revert, ownChangesAnswered } from "./edits.js";
import { initTextureView, fit, screenGeometry, dragPreview, labelLayout, panBy } from "./texture_view.js";
import { initFrameView, setPatternSource, setPreviewSource, setFrameSize, frameStats, frameUrl, pickAt } from "./frame_view.js";
import { initLibrary, currentPattern, uploadPattern } from "./panels/library.js";
import { initPlacements } from "./panels/placements.js";
import { initParams } from "./panels/params.js";
import { initHistory } from "./panels/history.js";
import { initPose } from "./panels/pose.js";
import { initActivation } from "./panels/activation.js";
import { initKeys, setKeysApi } from "./keys.js";
import { initLive, connect, disconnect } from "./live.js";
import { initPermalink, readLink, copyLink } from "./permalink.js";
import { openTransferDialog } from "./transfer.js";
import { initPropose } from "./propose.js";
import { trace, clearTrace } from "./trace.js";
import { bursting, withPending } from "./pending.js";

const $ = (id) => document.getElementById(id);
const api = new Api({ client: makeClientName(), signIn });

/// Reads the current scene again (after a 412, another person's edit, a reconnect).
/// Reads can overlap (two changes by someone else in quick succession) and their answers can come
/// back in either order: an answer older than the revision the editor has, or for a scene it has
/// left, is dropped, so a late read never takes the editor back.
async function reloadScene() {
  if (!store.sceneId) return;
  const id = store.sceneId;
  try {
    const answer = await api.get(scenePath(id));
    if (id !== store.sceneId || answer.revision < store.revision) return;
    if (answer.revision !== store.revision || JSON.stringify(answer.scene) !== JSON.stringify(store.doc)) {
      set({ doc: answer.scene, revision: answer.revision }, [Topic.DOC, Topic.REVISION]);
    }
  } catch (e) { notify(`Reading the scene: ${e.message}`, "error"); }
}

let lintReads = 0; // lint reads started (see loadLint)

/// Reads the scene's lint. Reads can overlap (quick revisions); only the newest read's answer is
/// shown, and none for a scene the editor has left.
async function loadLint() {
  const read = ++lintReads, id = store.sceneId;
  let lint;
  try { lint = await api.get(lintPath(id)); } catch { lint = []; }
  if (read === lintReads && id === store.sceneId) set({ lint });
}

let opening = 0; // scene opens started (see openScene)

/// Opens scene `id`; `link` (a permalink's fields) sets revision, time, camera and selection.
/// This window's changes to the scene it leaves are sent and answered there first. Opens can
/// overlap (arrow keys on the scene menu): only the newest one opens its scene.
async function openScene(id, link = {}) {
  const ticket = ++opening;
  await ownChangesAnswered();
  const answer = await api.get(scenePath(id));
  if (ticket !== opening) return;
  const model = await api.get(`/models/${encodeURIComponent(answer.scene.model)}`);
  if (ticket !== opening) return;
  // The height-map layout the scene uses (SPEC §8: its own UVs, or the generated layout where
  // they are missing or shared); null where there is none to draw (uv_layout "model" without UVs).
  const layoutMode = encodeURIComponent(answer.scene.uv_layout || "auto");
  const layout = await api.get(`/models/${encodeURIComponent(model.id)}/uv-layout?layout=${layoutMode}`).catch(() => null);
  if (ticket !== opening) return;
  clearUndo();
  const camera = { yaw: link.yaw ?? 0, pitch: link.pitch ?? 10, distance: link.distance ?? null, target: link.target ?? null };
  if (link.yaw === undefined && answer.scene.render && answer.scene.render.camera) {
    const c = answer.scene.render.camera;
    if (typeof c.yaw === "number") camera.yaw = c.yaw;
    if (typeof c.pitch === "number") camera.pitch = c.pitch;
    if (typeof c.distance === "number") camera.distance = c.distance;
  }
  if (link.size) setFrameSize(link.size);
  const pinned = link.revision !== undefined && link.revision !== answer.revision ? link.revision : null;
  set({
    sceneId: id, doc: answer.scene, revision: answer.revision, model, layout, camera,
    time: link.time ?? null, view: link.view || "shaded", pinnedRevision: pinned,
    selection: (link.selection || []).filter((s) => answer.scene.placements.some((p) => p.id === s)), solo: [],
    presence: new Map(),
    // A revision to compare against is the old scene's: another scene compares against patterns off.
    compare: id === store.sceneId ? store.compare : { ...store.compare, against: "off" },
  }, [Topic.SCENE, Topic.DOC, Topic.REVISION, Topic.MODEL, Topic.LAYOUT, Topic.CAMERA, Topic.TIME, Topic.VIEW, Topic.PINNED_REVISION,
      Topic.SELECTION, Topic.SOLO, Topic.PRESENCE, Topic.COMPARE]);
  $("scene").value = id;
  connect();
  fit();
}

/// The scene menu: each scene by its model's name and placement count (the id in the tooltip).
async function refreshSceneList(select) {
  const [scenes, models] = await Promise.all([api.get(SCENES_PATH).then((a) => a.scenes), api.get("/models").then((a) => a.models).catch(() => [])]);
  const names = new Map(models.map((m) => [m.id, m.name || m.id]));
  const esc = (t) => String(t).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
  $("scene").innerHTML = scenes.map((s) => {
    const name = names.get(s.model) || s.model.replace(/^builtin:/, "");
    return `<option value="${esc(s.id)}" title="scene ${esc(s.id)} on ${esc(s.model)}">${esc(name)} · ${s.placements} placement${s.placements === 1 ? "" : "s"}</option>`;
  }).join("");
  if (select) $("scene").value = select;
  return scenes;
}

function wireToolbar() {
  $("me").textContent = api.client;
  $("scene").onchange = () => openScene($("scene").value).catch((e) => notify(e.message, "error"));
  $("undo").onclick = () => undo();
  $("redo").onclick = () => redo();
  on([Topic.UNDO, Topic.REVISION], () => { $("undo").disabled = !canUndo(); $("redo").disabled = !canRedo(); });
  on(Topic.REVISION, () => { $("revision").textContent = `r${store.revision}`; });
  on([Topic.BUSY, Topic.SAVE_ERROR, Topic.ONLINE, Topic.REVISION], showSaveState);
  // Closing or reloading the window while an edit is still on its way would lose it: ask first.
  window.addEventListener("beforeunload", (e) => { if (store.busy > 0 || bursting()) { e.preventDefault(); e.returnValue = ""; } });
  // The layout buttons only: <main class="workspace"> carries data-layout too, and a click in the
  // workspace must not switch (and re-fit) the views.
  const layoutButtons = document.querySelectorAll("button[data-layout]");
  for (const b of layoutButtons)
    b.onclick = () => { if (store.layoutMode !== b.dataset.layout) set({ layoutMode: b.dataset.layout }); };
  on(Topic.LAYOUT_MODE, () => {
    document.querySelector(".workspace").dataset.layout = store.layoutMode;
    for (const b of layoutButtons) b.classList.toggle("on", b.dataset.layout === store.layoutMode);
  });
  $("newScene").onclick = () => $("newSceneFile").click();
  $("newSceneFile").onchange = () => { const f = $("newSceneFile").files[0]; if (f) newSceneFromModel(f); $("newSceneFile").value = ""; };
  $("download").onclick = downloadScene;
  $("load").onclick = () => $("loadFile").click();
  $("loadFile").onchange = () => { const f = $("loadFile").files[0]; if (f) loadSceneFile(f); $("loadFile").value = ""; };
  $("transferFrom").onclick = () => openTransferDialog(api);
  $("copyLink").onclick = async () => { await copyLink(); notify("Link copied: it opens this exact view.", "info"); };
  on([Topic.PINNED_REVISION, Topic.REVISION], () => {
    const b = $("pinned");
    b.hidden = store.pinnedRevision === null;
    if (b.hidden) return;
    b.innerHTML = `Showing revision ${store.pinnedRevision} from a link (the scene is at ${store.revision}).
      <button type="button" id="unpin">Show the latest</button><button type="button" id="revertPinned">Revert to revision ${store.pinnedRevision}</button>`;
    $("unpin").onclick = () => set({ pinnedRevision: null });
    $("revertPinned").onclick = () => revert(store.pinnedRevision);
  });
  // The scene menu counts placements: it follows once things are quiet.
  on(Topic.REVISION, () => whenIdle("scene-list", () => refreshSceneList(store.sceneId).catch(() => {}), 400));
  on(Topic.REVISION, () => whenIdle("lint", () => {
    forget(heightmapsPath(store.sceneId));
    set({ overlayRevision: store.revision }); // the overlay follows once things are quiet
    loadLint();
    emit(Topic.OVERLAY);
  }));
  // Files dropped anywhere: a .glb makes a new scene, an image becomes a pattern, anything else is refused.
  document.addEventListener("dragover", (e) => { if ([...e.dataTransfer.types].includes("Files")) e.preventDefault(); });
  document.addEventListener("drop", (e) => {
    const f = e.dataTransfer.files[0];
    if (!f) return;
    e.preventDefault();
    if (/\.glb$/i.test(f.name)) newSceneFromModel(f);
    else if (/\.json$/i.test(f.name)) loadSceneFile(f);
    else uploadPattern(f);
  });
}

/// The save indicator next to the revision: is what I changed on the server yet?
function showSaveState() {
  const el = $("saveState");
  const [state, text, title] =
    store.busy > 0 ? ["saving", "Saving…", "Your edits are being sent to the server"]
    : store.saveError !== null ? ["error", "Not saved", `Your last edit was refused: ${store.saveError}`]
    : !store.online ? ["offline", "Offline", "The connection to the server dropped: edits cannot be saved until it is back"]
    : ["saved", "✓ Saved", `Every edit is on the server (revision ${store.revision})`];
  el.dataset.state = state;
  el.textContent = text;
  el.title = title;
}

async function newSceneFromModel(f) {
  try {
    notify(`Uploading ${f.name}…`, "info", null, "newscene");
    const model = await api.json("POST", `/models?name=${encodeURIComponent(f.name.replace(/\.glb$/i, ""))}`,
                                 { body: f, headers: { "Content-Type": "model/gltf-binary" } });
    const scene = await api.send("POST", SCENES_PATH, { format: "dermis.scene/1", model: model.id, placements: [] });
    await refreshSceneList(scene.id);
    await openScene(scene.id);
    const joints = model.joint_count ?? model.joints;
    notify(`New scene on ${model.name || model.id}: ${model.triangles} triangles, ${joints} joint${joints === 1 ? "" : "s"}${model.has_uvs ? "" : ", no UVs"}.`, "info", null, "newscene");
  } catch (e) { notify(`New scene from ${f.name}: ${e.message}`, "error", null, "newscene"); }
}

function downloadScene() {
  const blob = new Blob([JSON.stringify(store.doc, null, 2) + "\n"], { type: "application/json" });
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = `${store.sceneId}-r${store.revision}.scene.json`;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

async function loadSceneFile(f) {
  let doc;
  try { doc = JSON.parse(await f.text()); } catch (e) { return notify(`${f.name} is not JSON: ${e.message}`, "error"); }
  if (await putScene(doc)) notify(`Loaded ${f.name} as revision ${store.revision}.`, "info");
}

async function start() {
  initImages(api);
  initEdits(api, reloadScene);
  setKeysApi(api);
  initTextureView($("textureView"), api);
  initFrameView($("frameView"), api);
  setPatternSource(currentPattern);
  setPreviewSource(dragPreview);
  initLibrary($("libraryPanel"), api);
  initPlacements($("placementsPanel"));
  initParams($("paramsPanel"), api);
  initHistory($("historyPanel"), api);
  initPose($("posePanel"));
  initActivation($("activationPanel"), api);
  initKeys({ fitTexture: fit });
  initPropose(api, $("propose"));
  initLive(api, reloadScene);
  initPermalink();
  wireToolbar();
  set({ layoutMode: window.innerWidth < 900 ? "texture" : "both" });
  try {
    set({ patterns: (await api.get("/patterns")).patterns });
    const link = readLink();
    let scenes = await refreshSceneList();
    if (!scenes.length) {
      const created = await api.send("POST", SCENES_PATH, { default_patterns: true });
      scenes = await refreshSceneList(created.id);
    }
    const id = link.scene && scenes.some((s) => s.id === link.scene) ? link.scene : scenes[0].id;
    if (link.scene && id !== link.scene) notify(`The link's scene ${link.scene} does not exist here; showing ${id}.`, "warn");
    await openScene(id, id === link.scene ? link : {});
  } catch (e) {
    notify(e instanceof ApiError ? e.message : String(e), "error");
  }
}

// For tests and benchmarks: a read-only look at the editor's state and its frame statistics.
window.dermisEditor = { store, frameStats, frameUrl, pickAt, disconnect, connect, api, screenGeometry, labelLayout, trace, clearTrace,
  select: (ids) => set({ selection: ids }), shownPlacement: (id) => withPending(placementById(id)), panTexture: panBy };

start();
