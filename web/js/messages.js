// Server errors in words for people: the API's messages name the function and the JSON pointer
// for scripts ("dermis::Service: If-Match: …", "dermis::parseScene: /placements/3/h: must be
// finite"); the editor shows "h of "elbow L": must be finite" instead. Only the wording changes:
// the code, field and status of the ApiError stay as the server sent them.

const FIELD_NAMES = { id: "", body: "", placement: "", theta_min: "θmin", theta_max: "θmax", h: "h", center: "centre", scale: "scale", rotation: "rotation",
                      joint: "joint", axis: "axis", pattern: "pattern", label: "label", target: "target", model: "model",
                      response: "response", enabled: "enabled" };

/// The message of ApiError `e` for a person; `doc` (the scene document, optional) names
/// placements by their labels.
export function inWords(e, doc = null) {
  if (!e) return "refused";
  let m = String(e.raw || e.message || e.code || "refused");
  // "dermis::Service::patchPlacement: ", "dermis-server: ", "dermis::Api: " …: who said it.
  m = m.replace(/^(?:dermis(?:::\w+)+|dermis-server|dermis)\s*:\s*/, "");
  // A leading JSON pointer or header name: the field, which we say in words.
  const pointer = /^(\/[^\s:]*|If-Match|X-Dermis-Client)\s*:\s*/.exec(m);
  if (pointer) m = m.slice(pointer[0].length);
  else if (e.field && m.startsWith(`${e.field}: `)) m = m.slice(e.field.length + 2);
  const field = fieldInWords(pointer ? pointer[1] : e.field, doc);
  if (e.code === "stale_revision") return "Someone else changed this placement first";
  return field ? `${field}: ${m}` : m.charAt(0).toUpperCase() + m.slice(1);
}

/// "/placements/3/h" → 'h of "elbow L"'; "/pose/joints/…" → "pose"; headers and "" → "".
function fieldInWords(field, doc) {
  if (!field || field === "If-Match" || field === "X-Dermis-Client") return "";
  const parts = field.split("/").slice(1).map((s) => s.replace(/~1/g, "/").replace(/~0/g, "~"));
  if (parts[0] === "placements" && parts.length >= 2) {
    const p = doc && doc.placements && /^\d+$/.test(parts[1]) ? doc.placements[+parts[1]] : null;
    const who = p ? `"${p.label || p.id}"` : `placement ${+parts[1] + 1}`;
    const key = parts[2];
    return key ? `${FIELD_NAMES[key] || key} of ${who}` : who;
  }
  if (field.startsWith("/")) return parts.map((k) => FIELD_NAMES[k] || k).join(" ");
  return field in FIELD_NAMES ? FIELD_NAMES[field] : field;
}
