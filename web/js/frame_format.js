// Which image format the 3D view asks frames in (the frame route's `format`): the fastest one
// that this browser can show, from the encode times dermis-bench measures (docs/benchmarks.md "Encoders",
// 512² frame on the 2-core reference machine).
//
// While a gesture runs (a drag, a slider) frames are previews: JPEG (quality 90), 4–15× faster
// to encode than any lossless format and 4× smaller. Otherwise frames are lossless: the faster of
// PNG and lossless WebP that the browser decodes — WebP is probed once at start-up by decoding a
// 1×1 lossless WebP with createImageBitmap (no network). PNG's multi-threaded encoder measures
// faster than libwebp's fastest lossless preset there (WebP is 17% smaller at 512²), so PNG is
// asked for today; update LOSSLESS_ENCODE_MS if the figures change. The default format (png) is left
// out of the URL, so frame URLs stay as they were.

/// Median encode milliseconds of a 512² frame per lossless format (dermis-bench "encoders").
export const LOSSLESS_ENCODE_MS = { png: 8.0, webp: 9.5 };

// A 1×1 lossless WebP (VP8L), opaque white.
const TINY_WEBP = "UklGRhoAAABXRUJQVlA4TA0AAAAvAAAAEAcQERGIiP4HAA==";

const decodes = { png: true, jpeg: true, webp: false };

/// Resolves once the WebP probe has finished (true when the browser decodes lossless WebP).
export const webpProbe = (async () => {
  try {
    if (typeof createImageBitmap !== "function") return false;
    const bytes = Uint8Array.from(atob(TINY_WEBP), (c) => c.charCodeAt(0));
    const bitmap = await createImageBitmap(new Blob([bytes], { type: "image/webp" }));
    decodes.webp = bitmap.width === 1 && bitmap.height === 1;
    bitmap.close?.();
  } catch {
    decodes.webp = false;
  }
  return decodes.webp;
})();

/// The lossless format to ask for: the fastest measured one the browser decodes.
export function losslessFormat() {
  return Object.entries(LOSSLESS_ENCODE_MS)
    .filter(([f]) => decodes[f])
    .sort((a, b) => a[1] - b[1])[0][0];
}

/// The `format` query value for a frame: "jpeg" while `previewing`, else the lossless format,
/// undefined when that is the server's default (png).
export function frameFormat(previewing) {
  if (previewing) return "jpeg";
  const f = losslessFormat();
  return f === "png" ? undefined : f;
}
