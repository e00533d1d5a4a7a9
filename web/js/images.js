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

const tinted = new Map(); // height-map path -> canvas (signed heights as colour and alpha)

/// A height map (a 16-bit grey PNG of the heightmaps route: 0.5 = flat) as an overlay: raised
/// skin warm, creases cool, flat skin transparent; null until loaded.
export function heightOverlay(path) {
  if (tinted.has(path)) return tinted.get(path);
  const bmp = image(path);
  if (!bmp) return null;
  const c = document.createElement("canvas");
  c.width = bmp.width;
  c.height = bmp.height;
  const g = c.getContext("2d", { willReadFrequently: true });
  g.drawImage(bmp, 0, 0);
  const px = g.getImageData(0, 0, c.width, c.height);
  const d = px.data;
  for (let i = 0; i < d.length; i += 4) {
    const h = (d[i] - 128) / 127; // −1 … 1
    const a = Math.min(1, Math.abs(h) * 3);
    if (h >= 0) { d[i] = 255; d[i + 1] = 170; d[i + 2] = 60; } else { d[i] = 70; d[i + 1] = 170; d[i + 2] = 255; }
    d[i + 3] = Math.round(a * 255);
  }
  g.putImageData(px, 0, 0);
  tinted.set(path, c);
  return c;
}

/// Forgets `path`s that start with `prefix` (e.g. an overlay of an older revision).
export function forget(prefix) {
  for (const k of [...cache.keys()]) if (k.startsWith(prefix)) cache.delete(k);
  for (const k of [...tinted.keys()]) if (k.startsWith(prefix)) tinted.delete(k);
}

export const patternImagePath = (id) => `/patterns/${encodeURIComponent(id)}/image`;
