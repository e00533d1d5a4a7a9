// The deformation model of SPEC §2 in the browser, for the parameters panel's plot only (the
// server computes every real height): t = clamp((θ − θmin)/(θmax − θmin), 0, 1); scale model
// (paper eq. 1) L_out = L·h·gain(t); bias model (paper eq. 2) L_out = max(h·(L − offset(t)), 0);
// t = 0 → 0 and t = 1 → L·h for every response.

export function normalizedT(theta, min, max) {
  if (max === min) return theta >= max ? 1 : 0;
  return Math.min(Math.max((theta - min) / (max - min), 0), 1);
}

const gain = { log2: (t) => Math.log2(1 + t), ln: (t) => Math.log(1 + t), linear: (t) => t, smoothstep: (t) => t * t * (3 - 2 * t) };
const offset = { log2: (t) => Math.log2(2 - t), ln: (t) => Math.log(2 - t), linear: (t) => 1 - t, smoothstep: (t) => 1 - t * t * (3 - 2 * t) };

/// L_out of pattern value L at t for a placement's model, response and h.
export function height(p, L, t) {
  if (t <= 0) return 0;
  if (t >= 1) return L * p.h;
  const r = p.response || "log2";
  if (p.model === "bias") return Math.max(p.h * (L - (offset[r] || offset.log2)(t)), 0);
  return L * p.h * (gain[r] || gain.log2)(t);
}
