// Live updates: the scene's server-sent events. A change by anyone else re-reads the document
// (this editor's own edits are already applied from their answers); presence events show who has
// what selected (our own selection is announced on change and every 10 s; entries lapse after
// 30 s); `resync` re-reads. When the stream drops, the offline banner shows; EventSource
// reconnects by itself and the editor re-reads the scene when it is back.

import { store, on, set, emit, Topic } from "./store.js";
import { setOffline } from "./notice.js";
import { eventsUrl, presencePath } from "./scene_resource.js";

let api, source = null, reload = async () => {}, presenceTimer = null, color = null, everOpen = false;

export function initLive(theApi, reloadScene) {
  api = theApi;
  reload = reloadScene;
  color = `hsl(${Math.floor(Math.random() * 360)}, 75%, 62%)`;
  on(Topic.SELECTION, announce);
  on(Topic.PRESENCE, renderPeople);
  setInterval(expirePresence, 2000);
}

export const myColor = () => color;

/// Sets the presence to a copy of it changed by `change(map)` (the store's Map is never changed
/// in place) and tells "presence".
function changePresence(change) {
  const presence = new Map(store.presence);
  change(presence);
  set({ presence });
}

/// The initials of a client name ("merry-wren-q1x9" → "MW"): a chip's text when many are here.
function initials(client) {
  const words = String(client).split(/[-_\s]+/).filter((w) => /^[a-z]/i.test(w));
  return (words.slice(0, 2).map((w) => w[0]).join("") || String(client).slice(0, 2)).toUpperCase();
}

/// The people on this scene, as chips in their colour (title: what they have selected). Up to
/// two chips show whole names; more show initials (the name in the title), so that a room full
/// of people still fits the toolbar's spare room, where the chips are clipped, never wrapped.
function renderPeople() {
  const box = document.getElementById("people");
  if (!box) return;
  box.innerHTML = "";
  const many = store.presence.size > 2;
  box.classList.toggle("many", many);
  for (const [client, who] of store.presence) {
    const chip = document.createElement("span");
    chip.className = "person";
    chip.dataset.client = client;
    chip.style.background = who.color || "#ccc";
    chip.textContent = many ? initials(client) : client;
    chip.setAttribute("aria-label", client);
    chip.title = who.selection.length ? `${client} has ${who.selection.join(", ")} selected` : `${client} is here`;
    box.append(chip);
  }
  fitPeople(box);
  if (!peopleObserver && typeof ResizeObserver === "function") {
    peopleObserver = new ResizeObserver(() => fitPeople(box));
    peopleObserver.observe(box);
  }
}

let peopleObserver = null;

/// Shows as many whole chips as the box has room for and a "+N" chip for the rest (its title
/// names them): no chip is ever cut in half. Reads layout, so call it after the chips change or
/// the box resizes.
function fitPeople(box) {
  box.querySelector(".more")?.remove();
  const chips = [...box.querySelectorAll(".person")];
  for (const c of chips) c.hidden = false;
  if (box.scrollWidth <= box.clientWidth + 0.5) return;
  const more = document.createElement("span");
  more.className = "person more";
  box.append(more);
  let shown = chips.length;
  do {
    chips[--shown].hidden = true;
    const rest = chips.slice(shown).map((c) => c.dataset.client);
    more.textContent = `+${rest.length}`;
    more.title = `Also here: ${rest.join(", ")}`;
    more.setAttribute("aria-label", `${rest.length} more: ${rest.join(", ")}`);
  } while (shown > 0 && box.scrollWidth > box.clientWidth + 0.5);
}

/// Opens the event stream of the current scene (closing any other).
export function connect() {
  if (source) source.close();
  everOpen = false;
  const id = store.sceneId;
  const es = (source = new EventSource(eventsUrl(id)));
  es.addEventListener("hello", (e) => {
    const wasOffline = !store.online;
    set({ online: true });
    setOffline(false);
    const ev = JSON.parse(e.data);
    if ((wasOffline || everOpen) && ev.revision !== store.revision) reload();
    else if (wasOffline) reload();
    everOpen = true;
    announce();
    api.get(presencePath(id)).then((answer) => store.sceneId === id && changePresence((presence) => {
      for (const who of answer.presence || [])
        if (who.client !== api.client)
          presence.set(who.client, { selection: who.selection, color: who.color, until: Date.now() + 1000 * who.expires_in });
    })).catch(() => {});
  });
  es.addEventListener("change", (e) => {
    const ev = JSON.parse(e.data);
    emit(Topic.EVENT);
    if (ev.scene !== store.sceneId) return;
    if (ev.revision <= store.revision) return; // older than what this editor has
    if (ev.client && ev.client === api.client && store.busy > 0) return; // ours: its answer brings the document
    reload();
  });
  es.addEventListener("resync", () => reload());
  es.addEventListener("presence", (e) => {
    const ev = JSON.parse(e.data);
    if (!ev.client || ev.client === api.client) return;
    if (ev.left) { changePresence((presence) => presence.delete(ev.client)); return; }
    const until = Date.now() + 1000 * (ev.expires_in || 30);
    changePresence((presence) => presence.set(ev.client, { selection: ev.selection || [], color: ev.color, until }));
  });
  es.onerror = () => {
    if (es !== source) return;
    set({ online: false });
    setOffline(true);
    if (es.readyState === EventSource.CLOSED) setTimeout(() => { if (es === source) connect(); }, 1500);
  };
  clearInterval(presenceTimer);
  presenceTimer = setInterval(announce, 10000);
}

/// Closes the stream (tests: a dropped connection).
export function disconnect() { if (source) source.close(); source = null; }

async function announce() {
  if (!store.sceneId || !store.online) return;
  const body = { client: api.client, selection: store.selection.slice(0, 100), color };
  try {
    await api.send("POST", presencePath(store.sceneId), body);
  } catch { /* presence is best effort: the next announcement tries again */ }
}

function expirePresence() {
  const now = Date.now();
  if ([...store.presence.values()].some((v) => v.until < now))
    changePresence((presence) => { for (const [k, v] of presence) if (v.until < now) presence.delete(k); });
}
