// Shared by the editor's browser suites (WebEditor*BrowserTest): Debian's Chromium through
// playwright-core against a real dermis-server on 127.0.0.1, a node-side API client (another
// person, or the test checking server state), helpers that wait for the editor, and a check
// runner that runs every check, reports each, and fails the suite if any failed.
import { chromium } from "playwright-core";
import { mkdirSync } from "node:fs";
import { createHash } from "node:crypto";
import { join } from "node:path";
import { startServer } from "../lib/server.mjs";

export { startServer };

/// The folder where the suites save screenshots ($DERMIS_TEST_OUT, default ./editor-screenshots).
export const shotDir = process.env.DERMIS_TEST_OUT || join(process.cwd(), "editor-screenshots");
mkdirSync(shotDir, { recursive: true });

export const launch = () => chromium.launch({ executablePath: process.env.CHROMIUM || "/usr/bin/chromium", args: ["--no-sandbox"] });

/// A node-side client of `base`: { status, body, headers } of a request.
export function apiClient(base, client = "node-test") {
  return async (method, path, body, headers = {}) => {
    const h = { "X-Dermis-Client": client, ...headers };
    if (body !== undefined) h["Content-Type"] = "application/json";
    const r = await fetch(base + "/api/v1" + path, { method, headers: h, body: body !== undefined ? JSON.stringify(body) : undefined });
    const type = r.headers.get("content-type") || "";
    const data = type.includes("json") ? await r.json() : Buffer.from(await r.arrayBuffer());
    return { status: r.status, body: data, headers: r.headers };
  };
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/// Polls `fn` (async) until it returns a truthy value; throws `what` after `ms`.
export async function until(fn, what, ms = 10000) {
  const t0 = Date.now();
  let last;
  while (Date.now() - t0 < ms) {
    last = await fn();
    if (last) return last;
    await sleep(50);
  }
  throw new Error(`timed out: ${what} (last: ${JSON.stringify(last)})`);
}

/// Opens the editor at `url` in a new page of `context`; waits for a decoded frame and the scene.
export async function openEditor(context, url, viewport = { width: 1600, height: 1000 }) {
  const page = await context.newPage();
  await page.setViewportSize(viewport);
  page.errors = [];
  page.on("pageerror", (e) => page.errors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => window.dermisEditor && window.dermisEditor.store.doc, null, { timeout: 30000 });
  await waitFrame(page);
  return page;
}

/// Waits until the 3D view shows a decoded frame newer than `seq` (its sequence number).
export async function waitFrame(page, seq = 0, timeout = 30000) {
  await page.waitForFunction((s) => {
    const i = document.getElementById("frame");
    return i && i.complete && i.naturalWidth > 0 && +(i.dataset.seq || 0) > s;
  }, seq, { timeout });
  return page.$eval("#frame", (i) => +i.dataset.seq);
}

/// Waits until the frame on screen is the one the editor's state asks for, and returns its
/// SHA-256 (hex) — the bytes the server sent for that URL.
export async function settledFrameHash(page) {
  await page.waitForFunction(() => {
    const i = document.getElementById("frame");
    return i && i.complete && i.naturalWidth > 0 && i.dataset.url === window.dermisEditor.frameUrl();
  }, null, { timeout: 30000 });
  const bytes = await page.evaluate(async () => {
    const url = document.getElementById("frame").dataset.url;
    const b = await (await fetch("/api/v1" + url)).arrayBuffer();
    return Array.from(new Uint8Array(b));
  });
  return createHash("sha256").update(Buffer.from(bytes)).digest("hex");
}

/// Waits until the editor is quiet — no gesture, no edit queued or in flight, twice 100 ms apart —
/// and has the server's revision of its scene (`api` is an apiClient of the same server).
export async function settled(page, api) {
  let quiet = 0;
  await until(async () => {
    const s = await page.evaluate(() => { const t = window.dermisEditor.store; return { busy: t.busy, gestures: t.gestures, revision: t.revision, id: t.sceneId }; });
    const server = (await api("GET", `/scenes/${s.id}`)).body.revision;
    quiet = s.busy === 0 && s.gestures === 0 && s.revision === server ? quiet + 1 : 0;
    if (quiet < 2) await sleep(100);
    return quiet >= 2;
  }, "the editor is quiet and at the server's revision", 15000);
}

/// The editor's state fields (JSON-safe).
export const state = (page) => page.evaluate(() => {
  const s = window.dermisEditor.store;
  return { sceneId: s.sceneId, revision: s.revision, doc: s.doc, selection: s.selection, solo: s.solo, time: s.time, online: s.online, pinnedRevision: s.pinnedRevision, camera: s.camera };
});

/// Selects placement `id` by clicking its row's name in the placement list, as a person does;
/// clicks again if the list was re-rendered under the click (an event from another client) until
/// the editor's selection is exactly [id].
export async function selectPlacement(page, id) {
  const row = `#placementList li[data-placement="${id}"] .name`;
  await until(async () => {
    await page.click(row, { timeout: 3000 }).catch(() => {});
    const now = await page.evaluate(() => window.dermisEditor.store.selection);
    return now.length === 1 && now[0] === id;
  }, `${id} selected`);
}

/// A slow link's way back: requests of `page` whose URL `match` takes (a Playwright URL matcher)
/// and whose method is in `methods` (all when omitted) reach the server at once; their answers
/// arrive `ms` late. Only the first `first` such requests are held. Returns { seen, held,
/// delivered, stop }: the requests seen, held and whose held answer has been delivered so far,
/// and stop() — the route's removal.
export async function holdAnswers(page, match, { methods = null, ms = 1000, first = Infinity } = {}) {
  const h = { seen: 0, held: 0, delivered: 0 };
  const handler = async (route) => {
    if (methods && !methods.includes(route.request().method())) return route.continue();
    if (h.seen++ >= first) return route.continue();
    const answer = await route.fetch(); // the server has it now
    h.held++;
    await sleep(ms);
    await route.fulfill({ response: answer });
    h.delivered++;
  };
  await page.route(match, handler);
  h.stop = () => page.unroute(match, handler);
  return h;
}

/// Screen geometry (client px) of a placement's footprint in the texture view.
export const footprint = (page, id) => page.evaluate((pid) => {
  const g = window.dermisEditor.screenGeometry(pid);
  return g && { center: g.center, corners: g.corners, rotate: g.rotate, pxPerUV: g.pxPerUV };
}, id);

export const screenshot = (page, name) => page.screenshot({ path: join(shotDir, name) });

/// Runs `checks` ([name, async fn]) in order; prints each result; returns the failure count.
export async function runChecks(suite, checks) {
  let failures = 0;
  for (const [name, fn] of checks) {
    const t0 = Date.now();
    try {
      await fn();
      console.log(`  ok   ${name} (${Date.now() - t0} ms)`);
    } catch (e) {
      ++failures;
      console.log(`  FAIL ${name}: ${e.stack || e.message}`);
    }
  }
  console.log(`${suite}: ${failures ? `${failures} of ${checks.length} checks FAILED` : `${checks.length} checks passed`}`);
  return failures;
}

/// Runs a suite: `body` (async, returns the failure count; a throw counts as one failure), then
/// `cleanup`; exits the process 0 when nothing failed, else 1.
export async function runSuite(name, body, cleanup) {
  let failures = 1;
  try {
    failures = await body();
  } catch (e) {
    console.error(`${name}: FAILED:`, e.stack || e.message);
    failures = Math.max(failures, 1);
  } finally {
    await cleanup();
  }
  process.exit(failures ? 1 : 0);
}

/// Counts the edit requests (non-GET to /api/v1/scenes/, except presence) a page sends.
export function countEdits(page) {
  const log = [];
  page.on("request", (r) => {
    const u = new URL(r.url());
    if (r.method() !== "GET" && u.pathname.startsWith("/api/v1/scenes/") && !u.pathname.endsWith("/presence")) log.push({ method: r.method(), path: u.pathname, body: r.postData(), at: Date.now() });
  });
  return log;
}
