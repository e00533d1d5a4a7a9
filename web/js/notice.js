// Notices: short messages in words at the bottom of the window (errors stay until dismissed or
// replaced by more; others fade after a few seconds), and the offline banner. Every server error
// the editor meets is shown here. Screen readers hear them (role=alert / status).

const box = () => document.getElementById("notices");

/// Shows `message`; kind: info | warn | error. `action` ({label, run}) adds a button (e.g. Undo)
/// that runs once and closes the notice; such a notice stays a little longer. A notice with a
/// `key` replaces the one shown before with that key (undo after undo: one notice, the latest).
export function notify(message, kind = "info", action = null, key = null) {
  const list = box();
  if (!list) return;
  if (key) for (const old of list.querySelectorAll(`.notice[data-key="${CSS.escape(key)}"]`)) old.remove();
  const item = document.createElement("div");
  item.className = `notice ${kind}`;
  if (key) item.dataset.key = key;
  item.setAttribute("role", kind === "error" || kind === "warn" ? "alert" : "status");
  const text = document.createElement("span");
  text.textContent = message;
  const close = document.createElement("button");
  close.type = "button";
  close.textContent = "×";
  close.setAttribute("aria-label", "dismiss");
  close.onclick = () => item.remove();
  item.append(text);
  if (action) {
    const b = document.createElement("button");
    b.type = "button";
    b.className = "action";
    b.textContent = action.label;
    b.onclick = () => { item.remove(); action.run(); };
    item.append(b);
  }
  item.append(close);
  list.append(item);
  while (list.children.length > 4) list.firstElementChild.remove();
  if (kind === "info") setTimeout(() => item.remove(), action ? 10000 : 4000);
  else setTimeout(() => item.remove(), 15000);
}

/// Shows or hides the offline banner.
export function setOffline(offline) {
  const b = document.getElementById("offline");
  if (b) b.hidden = !offline;
}
