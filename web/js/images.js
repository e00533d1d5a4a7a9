// Image cache of the editor: pattern images, the model's base-colour texture and height-map
// overlays, loaded once per URL (through the API client, so sign-in applies) and kept as
// ImageBitmaps. `onLoad` listeners redraw when one arrives. A failed load is remembered as null.

const cache = new Map(); // url -> ImageBitmap | null | Promise
const loadedListeners = new Set();
let api = null;

export function initImages(theApi) { api = theApi; }
export function onImageLoaded(fn) { loadedListeners.add(fn); }

/// The bitmap of `path` (under /api/v1) if loaded; starts loading it otherwise and returns null.
export function image(path) {
  const hit = cache.get(path);
  if (hit === undefined) {
    const p = api.blob(path).then((b) => createImageBitmap(b)).then(
      (bmp) => { cache.set(path, bmp); for (const fn of loadedListeners) fn(path); },
      () => { cache.set(path, null); });
    cache.set(path, p);
    return null;
  }
  return hit instanceof Promise ? null : hit;
}

/// Forgets `path`s that start with `prefix` (e.g. an overlay of an older revision).
export function forget(prefix) {
  for (const k of [...cache.keys()]) if (k.startsWith(prefix)) cache.delete(k);
}

export const patternImagePath = (id) => `/patterns/${encodeURIComponent(id)}/image`;
