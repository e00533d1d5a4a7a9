// Scene resource of the API: the one place that spells the scene routes (/scenes, /scenes/{id}
// and what lies under it) and reads the scene's revision list, with one limit for every view of
// it (history panel, compare "against"). Paths are under /api/v1, as the Api client takes them;
// the *Url builders add the prefix for what the browser loads by itself (<img>, EventSource). It
// keeps no state: the scene id is an argument (the store's, or one a caller kept).

import { API, query } from "./api.js";

/// The most revisions a list of them shows (newest first).
export const REVISION_LIMIT = 40;

/// The scene collection (GET: the list, POST: a new scene).
export const SCENES_PATH = "/scenes";

/// Scene `id` (GET: its document; edits: `sub`, e.g. "/placements/{pid}", "/pose", "/revert").
export const scenePath = (id, sub = "") => `${SCENES_PATH}/${id}${sub}`;

export const lintPath = (id) => scenePath(id, "/lint");
export const revisionsPath = (id, limit = REVISION_LIMIT) => scenePath(id, `/revisions${query({ limit })}`);
export const presencePath = (id) => scenePath(id, "/presence");
export const eventsUrl = (id) => API + scenePath(id, "/events");
export const proposePath = (id) => scenePath(id, "/propose");
export const transferPath = (id, params) => scenePath(id, `/transfer${query(params)}`);
export const driversPath = (id, params) => scenePath(id, `/drivers${query(params)}`);
export const activationPath = (id, clip, fps) => scenePath(id, `/activation?clip=${encodeURIComponent(clip)}&fps=${fps}`);
/// The camera that frames what `q` (URLSearchParams) names.
export const focusPath = (id, q) => scenePath(id, `/focus?${q}`);
export const outlinePath = (id, placementId) => scenePath(id, `/placements/${encodeURIComponent(placementId)}/outline`);
export const framePath = (id, params) => scenePath(id, `/frame${query(params)}`);
export const frameDiffPath = (id, params) => scenePath(id, `/frame-diff${query(params)}`);
/// What is at a frame pixel (`params`: x, y and the frame's camera).
export const pickPath = (id, params) => scenePath(id, `/pick${query(params)}`);
/// What is at a point of the texture (u, v as they are, not rounded).
export const pickUVPath = (id, uv) => scenePath(id, `/pick?u=${uv[0]}&v=${uv[1]}`);
export const sweepUrl = (id, params) => API + scenePath(id, `/sweep${query(params)}`);
export const turntableUrl = (id, params) => API + scenePath(id, `/turntable${query(params)}`);
/// Every height map of the scene starts with this path (images.js forget()).
export const heightmapsPath = (id) => scenePath(id, "/heightmaps/");
export const heightmapPath = (id, target, revision) => `${heightmapsPath(id)}${target}?revision=${revision}`;

/// The scene's revisions, newest first (the answer of GET revisions: {revisions: [...]}), the
/// last REVISION_LIMIT of them; rejects with the Api's ApiError.
export const fetchRevisions = (api, id) => api.get(revisionsPath(id));
