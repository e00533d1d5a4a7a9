// WebViewerBrowserTest — the viewer (web/index.html) in Debian's Chromium, driven by
// playwright-core, against a real dermis-server on 127.0.0.1 with a fresh data folder.
// Usage: node viewer.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the page lists the scene and shows a rendered frame; dragging a footprint in the
// texture-space canvas moves that placement on the server; an edit made through the API by
// another client reaches the page by server-sent events and a new frame is shown.
import { chromium } from "playwright-core";
import assert from "node:assert/strict";
import { startServer } from "../lib/server.mjs";

const exe = process.argv[2];
const server = await startServer(exe, [], "dermis-web-");
const base = server.base;
const api = async (method, path, body) => {
  const r = await fetch(base + "/api/v1" + path, {
    method, headers: body ? { "Content-Type": "application/json" } : {}, body: body ? JSON.stringify(body) : undefined,
  });
  return r.json();
};

const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || "/usr/bin/chromium", args: ["--no-sandbox"] });
let failed = false;
try {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  await page.goto(base + "/");
  // The scene list and a first frame.
  await page.waitForFunction(() => document.querySelectorAll("#scene option").length > 0, null, { timeout: 30000 });
  const sceneId = await page.$eval("#scene", (s) => s.value);
  assert.match(sceneId, /^s_[0-9a-f]{16}$/);
  await page.waitForFunction(() => { const i = document.getElementById("frame"); return i.complete && i.naturalWidth === 512; }, null, { timeout: 30000 });
  const firstSrc = await page.$eval("#frame", (i) => i.src);

  // Drag the "stomach" footprint 40 px to the right in the 512-px texture-space canvas.
  const before = (await api("GET", `/scenes/${sceneId}`)).scene.placements.find((p) => p.id === "stomach");
  const box = await page.$eval("#uv", (c) => { const r = c.getBoundingClientRect(); return { x: r.x, y: r.y }; });
  const x = box.x + before.center[0] * 512, y = box.y + before.center[1] * 512;
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + 20, y, { steps: 4 });
  await page.mouse.move(x + 40, y, { steps: 4 });
  await page.mouse.up();
  let after = before;
  for (let i = 0; i < 50 && after.center[0] === before.center[0]; ++i) {
    await new Promise((r) => setTimeout(r, 100));
    after = (await api("GET", `/scenes/${sceneId}`)).scene.placements.find((p) => p.id === "stomach");
  }
  assert.ok(Math.abs(after.center[0] - (before.center[0] + 40 / 512)) < 3 / 512, `center ${after.center} after the drag from ${before.center}`);
  assert.ok(Math.abs(after.center[1] - before.center[1]) < 3 / 512);

  // Another client edits the pose: the page hears of it and shows a new frame.
  const edited = await api("PATCH", `/scenes/${sceneId}/pose`, { time: 0.3 });
  await page.waitForFunction((rev) => document.getElementById("status").textContent.includes(`revision ${rev}`), edited.revision, { timeout: 30000 });
  await page.waitForFunction((src) => { const i = document.getElementById("frame"); return i.src !== src && i.complete && i.naturalWidth === 512; }, firstSrc, { timeout: 30000 });
  assert.deepEqual(errors, []);
  console.log("WebViewerBrowserTest: passed");
} catch (e) {
  failed = true;
  console.error("WebViewerBrowserTest: FAILED:", e.message);
} finally {
  await browser.close();
  server.stop();
}
process.exit(failed ? 1 : 0);
