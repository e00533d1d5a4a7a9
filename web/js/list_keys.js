// Keyboard walking of a one-Tab-stop list (roving focus, as the placements and history lists do):
// ↑/↓, Home and End pick the row after/before, the first or the last one.

/// The <li> row of `list` that `e` (a keydown inside the list) moves to, or null when the key is
/// none of ↑ ↓ Home End, a modifier is held or the focus is on no row. When a row is returned the
/// key is taken: its default is prevented and it does not bubble (arrows here walk the list
/// instead of nudging the selection).
export function rowForListKey(e, list) {
  if (e.altKey || e.ctrlKey || e.metaKey || e.shiftKey) return null;
  const rows = [...list.querySelectorAll("li")];
  const i = rows.findIndex((li) => li.contains(document.activeElement));
  const j = i < 0 ? undefined : { ArrowUp: i - 1, ArrowDown: i + 1, Home: 0, End: rows.length - 1 }[e.key];
  if (j === undefined) return null;
  e.preventDefault();
  e.stopPropagation();
  return rows[Math.min(rows.length - 1, Math.max(0, j))];
}
