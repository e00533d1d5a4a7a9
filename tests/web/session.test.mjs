// WebSessionBrowserTest — signing in to a server started with --token, in Debian's Chromium
// driven by playwright-core, against a real dermis-server on 127.0.0.1 with a fresh data folder.
// Usage: node session.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the page asks for the token with its sign-in form (and shows no frame before); a wrong
// token shows an error and keeps the form; the right token (Enter submits) shows a frame; the
// session cookie is HttpOnly and SameSite=Strict, and the page keeps the token nowhere (field
// emptied, no script-visible cookie, no web storage); an EventSource on the scene hears of an
// edit made through the API with the bearer token and of one made from the page with the cookie;
// after DELETE /session the API answers 401 and a reload asks for the token again.
import { chromium } from "playwright-core";
import assert from "node:assert/strict";
import { startServer } from "../lib/server.mjs";

const exe = process.argv[2];
const token = "browser-s3cret-" + Math.random().toString(36).slice(2);
const server = await startServer(exe, ["--token", token], "dermis-session-");
const base = server.base;
// Another client: node's fetch with the bearer token.
const api = async (method, path, body) => {
  const headers = { Authorization: `Bearer ${token}` };
  if (body) headers["Content-Type"] = "application/json";
  const r = await fetch(base + "/api/v1" + path, { method, headers, body: body ? JSON.stringify(body) : undefined });
  return { status: r.status, body: r.status === 204 ? {} : await r.json() };
};
const visible = (page, id) => page.$eval(`#${id}`, (e) => !e.hidden && e.getBoundingClientRect().height > 0);

const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || "/usr/bin/chromium", args: ["--no-sandbox"] });
let failed = false;
try {
  // Without credentials the API refuses.
  assert.equal((await fetch(base + "/api/v1/scenes")).status, 401);

  const context = await browser.newContext();
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  await page.goto(base + "/");

  // The sign-in form appears; no frame has been shown.
  await page.waitForFunction(() => !document.getElementById("signin").hidden, null, { timeout: 30000 });
  assert.ok(await visible(page, "signin"), "the sign-in form is visible");
  assert.equal(await page.$eval("#frame", (i) => i.naturalWidth), 0);
  assert.equal(await page.evaluate(() => document.activeElement && document.activeElement.id), "token");

  // A wrong token: an error, the form stays, no cookie.
  await page.fill("#token", "not-the-token");
  await page.press("#token", "Enter");
  await page.waitForFunction(() => document.getElementById("signinError").textContent.length > 0, null, { timeout: 10000 });
  assert.ok(await visible(page, "signin"), "the form stays after a wrong token");
  assert.equal(await page.$eval("#token", (i) => i.value), "");
  assert.equal((await context.cookies()).length, 0);

  // The right token: the form goes, the scene list and a frame appear.
  await page.fill("#token", token);
  await page.press("#token", "Enter");
  await page.waitForFunction(() => document.getElementById("signin").hidden, null, { timeout: 10000 });
  await page.waitForFunction(() => document.querySelectorAll("#scene option").length > 0, null, { timeout: 30000 });
  const sceneId = await page.$eval("#scene", (s) => s.value);
  assert.match(sceneId, /^s_[0-9a-f]{16}$/);
  await page.waitForFunction(() => { const i = document.getElementById("frame"); return i.complete && i.naturalWidth === 512; }, null, { timeout: 30000 });

  // The session lives in an HttpOnly, SameSite=Strict cookie; the page keeps the token nowhere.
  const cookies = await context.cookies();
  const session = cookies.find((c) => c.name === "dermis_session");
  assert.ok(session, `a dermis_session cookie: ${JSON.stringify(cookies)}`);
  assert.match(session.value, /^[0-9a-f]{32}$/);
  assert.equal(session.httpOnly, true);
  assert.equal(session.sameSite, "Strict");
  assert.equal(session.path, "/api/v1");
  assert.ok(session.expires > Date.now() / 1000 + 3600, "the cookie lasts hours");
  const kept = await page.evaluate((t) => ({
    cookie: document.cookie, local: localStorage.length, session: sessionStorage.length,
    field: document.getElementById("token").value, html: document.documentElement.outerHTML.includes(t),
  }), token);
  assert.deepEqual(kept, { cookie: "", local: 0, session: 0, field: "", html: false });

  // An EventSource on the scene (the cookie authorises it) hears of an edit made through the API
  // by another client with the bearer token…
  await page.evaluate((id) => {
    window.heard = [];
    window.hello = false;
    const es = new EventSource(`/api/v1/scenes/${id}/events`);
    es.addEventListener("hello", () => { window.hello = true; });
    es.addEventListener("change", (e) => window.heard.push(JSON.parse(e.data)));
  }, sceneId);
  await page.waitForFunction(() => window.hello, null, { timeout: 10000 });
  const edited = await api("PATCH", `/scenes/${sceneId}/pose`, { time: 0.3 });
  assert.equal(edited.status, 200);
  await page.waitForFunction((rev) => window.heard.some((e) => e.revision === rev), edited.body.revision, { timeout: 10000 });
  // …and the page's own stream shows it too.
  await page.waitForFunction((rev) => document.getElementById("revision").textContent === `r${rev}`, edited.body.revision, { timeout: 30000 });

  // An edit from the page with the cookie alone.
  const fromPage = await page.evaluate(async (id) => {
    const r = await fetch(`/api/v1/scenes/${id}/pose`, { method: "PATCH", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ time: 0.6 }) });
    return { status: r.status, body: await r.json() };
  }, sceneId);
  assert.equal(fromPage.status, 200);
  await page.waitForFunction((rev) => window.heard.some((e) => e.revision === rev), fromPage.body.revision, { timeout: 10000 });

  // Sign-out: the cookie stops working, and a reload asks for the token again.
  const out = await page.evaluate(async () => (await fetch("/api/v1/session", { method: "DELETE" })).status);
  assert.equal(out, 204);
  assert.equal(await page.evaluate(async () => (await fetch("/api/v1/scenes")).status), 401);
  assert.equal((await context.cookies()).filter((c) => c.name === "dermis_session").length, 0);
  await page.reload();
  await page.waitForFunction(() => !document.getElementById("signin").hidden, null, { timeout: 30000 });

  assert.deepEqual(errors, []);
  console.log("WebSessionBrowserTest: passed");
} catch (e) {
  failed = true;
  console.error("WebSessionBrowserTest: FAILED:", e.message);
} finally {
  await browser.close();
  server.stop();
}
process.exit(failed ? 1 : 0);
