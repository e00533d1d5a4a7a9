// WebEditorCollabBrowserTest — several people, links and a dropped connection, in Debian's
// Chromium (playwright-core) against a real dermis-server on 127.0.0.1.
// Usage: node editor_collab.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: an edit in one browser context appears in another within 1 s; the other's selection
// shows as presence; a stale edit (its sender had not heard of the first change) shows the 412
// notice and leaves the first person's change intact; a permalink opened in a fresh context gives
// the identical frame (SHA-256 of the bytes); killing the server shows the offline banner, which
// clears when it is back (same port, same data) and the editor re-syncs; the scene document
// downloads; a dropped .glb makes a new scene; Transfer from… another scene previews what comes
// over (and what does not) and applies it in one revision; two quick changes by someone else whose
// reads answer out of order leave the editor at the newest revision; with every edit's answer held
// back 1 s: D right after `]` copies the turned placement, two quick Alt+↓ move a row two places, a
// key burst waiting when another scene is opened goes to its own scene (the other untouched, its
// undo steps left behind), and a deletion's Undo clicked in another scene does not touch it.
// Eight people on a scene at 1280×720 and 1450×900: the toolbar stays one row, the page the
// window's width, the chips show initials (the name in the title), none is cut, a "+N" chip counts
// the rest. Screenshot: editor-collab-people-1450.png.
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { startServer, launch, apiClient, openEditor, settledFrameHash, state, screenshot, runChecks, runSuite, until, sleep, selectPlacement, holdAnswers } from "./editor_lib.mjs";

const exe = process.argv[2];
let server = await startServer(exe, [], "dermis-editor-collab-");
const api = apiClient(server.base);
const browser = await launch();
await runSuite("WebEditorCollabBrowserTest", async () => {
  const ctxA = await browser.newContext(), ctxB = await browser.newContext();
  const a = await openEditor(ctxA, server.base + "/");
  const sceneId = (await state(a)).sceneId;
  const b = await openEditor(ctxB, `${server.base}/?scene=${sceneId}`);
  const serverPlacement = async (id) => (await api("GET", `/scenes/${sceneId}`)).body.scene.placements.find((p) => p.id === id);
  const select = async (page, id) => { await selectPlacement(page, id); await page.focus("#uv"); };

  let failures = await runChecks("WebEditorCollabBrowserTest", [
    ["an edit in one context appears in the other (the delay printed)", async () => {
      assert.equal((await state(b)).sceneId, sceneId);
      await select(a, "stomach");
      const before = (await state(b)).doc.placements.find((p) => p.id === "stomach");
      const t0 = Date.now();
      await a.keyboard.press("Shift+ArrowRight");
      // A functional check, not a timed one (speed is measured by benchmarks: a 1 s limit failed
      // once in CI beside a GL suite on two cores); the delay is printed.
      await b.waitForFunction((x) => window.dermisEditor.store.doc.placements.find((p) => p.id === "stomach").center[0] > x + 0.005, before.center[0], { timeout: 10000 });
      console.log(`    seen by the other context after ${Date.now() - t0} ms`);
    }],
    ["the other person's selection shows as presence", async () => {
      const meA = await a.$eval("#me", (e) => e.textContent);
      await b.waitForFunction((who) => { const p = window.dermisEditor.store.presence.get(who); return p && p.selection.includes("stomach"); }, meA, { timeout: 15000 });
      const chip = await b.$eval(`#people .person[data-client="${meA}"]`, (e) => e.title);
      assert.match(chip, /stomach/);
    }],
    ["eight people on a scene at 1280×720 and 1450×900: the chips give way, the page stays the window's width", async () => {
      // Before the fix, the chips' row widened the page's one grid column: at 1280 px the
      // parameters panel left the window; and 1401–1560 px wrapped the toolbar to two rows.
      const others = ["merry-wren-q1", "lucid-heron-q2", "keen-puma-q3", "eager-ibex-q4", "fleet-lynx-q5", "calm-koi-q6", "deft-finch-q7"];
      const here = async () => { // presence lapses after 30 s: said again before each width
        for (const client of others)
          assert.equal((await api("POST", `/scenes/${sceneId}/presence`, { client, selection: ["neck"], color: "#7fd0ff" })).status, 200);
      };
      // The chips are fitted again by a ResizeObserver, which runs at the next rendering step.
      const frames = () => p.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      await here();
      const p = await openEditor(ctxB, `${server.base}/?scene=${sceneId}`, { width: 1280, height: 720 });
      for (const [width, height] of [[1280, 720], [1450, 900]]) {
        await here();
        await p.setViewportSize({ width, height });
        await until(async () => (await p.$$eval("#people .person[data-client]", (cs) => cs.length)) >= others.length, "the chips of everyone here");
        await p.evaluate(() => { document.getElementById("me").textContent = "nimble-marten-wwww"; });
        await frames();
        const m = await p.evaluate(() => {
          const r = (s) => document.querySelector(s).getBoundingClientRect();
          const box = r("#people");
          const shown = [...document.querySelectorAll("#people .person[data-client]")].filter((c) => !c.hidden);
          const cut = shown.filter((c) => { const q = c.getBoundingClientRect(); return q.left < box.left - 0.5 || q.right > box.right + 0.5; });
          const more = document.querySelector("#people .more");
          return { toolbar: r(".toolbar").height, help: r("#helpButton").right, params: r("#paramsPanel").right, page: document.documentElement.scrollWidth,
                   shown: shown.length, cut: cut.length, more: more ? +more.textContent.slice(1) : 0, moreTitle: more ? more.title : "",
                   here: window.dermisEditor.store.presence.size };
        });
        assert.equal(m.cut, 0, `no chip cut at ${width} px`);
        assert.ok(m.here >= others.length, `everyone is here (${m.here})`);
        assert.equal(m.shown + m.more, m.here, `the chips shown (${m.shown}) and "+${m.more}" count everyone here`);
        if (m.more) assert.match(m.moreTitle, /^Also here: /);
        if (width >= 1450) assert.ok(m.shown >= 2, `at ${width} px two or more chips show (${m.shown})`);
        assert.ok(m.toolbar < 44, `one toolbar row at ${width} px (${m.toolbar} px)`);
        assert.ok(m.help <= width && m.params <= width + 0.5, `the ? button (${m.help}) and the parameters panel (${m.params}) are inside the ${width} px window`);
        assert.ok(m.page <= width, `the page is the window's width (${m.page} px)`);
      }
      // Many people: initials in the chips, the whole name in the title and the accessible name.
      const chip = await p.$eval(`#people .person[data-client="merry-wren-q1"]`, (c) => [c.textContent, c.getAttribute("aria-label"), c.title]);
      assert.equal(chip[0], "MW");
      assert.equal(chip[1], "merry-wren-q1");
      assert.match(chip[2], /^merry-wren-q1 has neck selected/);
      await screenshot(p, "editor-collab-people-1450.png");
      await p.close();
    }],
    ["a stale edit shows the 412 notice and leaves the first change intact", async () => {
      // B stops hearing events, so it edits an old revision.
      await b.evaluate(() => window.dermisEditor.disconnect());
      await select(b, "neck");
      await select(a, "neck");
      const neck0 = await serverPlacement("neck");
      await a.keyboard.press("Shift+ArrowDown");
      const afterA = await until(async () => { const p = await serverPlacement("neck"); return p.center[1] > neck0.center[1] && p; }, "A's nudge on the server");
      await b.keyboard.press("Shift+ArrowLeft");
      await b.waitForFunction(() => [...document.querySelectorAll("#notices .notice")].some((n) => /Someone else changed this placement/.test(n.textContent)), null, { timeout: 15000 });
      await sleep(300);
      assert.deepEqual(await serverPlacement("neck"), afterA, "A's change is intact");
      // B re-read the scene: it shows A's change now.
      await until(async () => JSON.stringify((await state(b)).doc.placements.find((p) => p.id === "neck")) === JSON.stringify(afterA), "B re-synced");
      await screenshot(b, "editor-stale-notice.png");
      await b.evaluate(() => window.dermisEditor.connect());
    }],
    ["a permalink opened in a fresh context shows the identical frame", async () => {
      // A orbits, scrubs the time and selects; then copies the link.
      const stage = await a.$eval("#frameStage", (e) => { const r = e.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; });
      await a.mouse.move(stage[0], stage[1]);
      await a.mouse.down();
      await a.mouse.move(stage[0] + 60, stage[1] + 20, { steps: 5 });
      await a.mouse.up();
      // The pointer leaves the 3D view: a hover outline is this window's, not part of the link
      // (left there, A's frame could carry hover= once the hover pick lands: slow under ASan).
      await a.mouse.move(2, 2);
      await a.$eval("#time", (el) => { el.value = "0.8"; el.dispatchEvent(new Event("input", { bubbles: true })); });
      await select(a, "elbow_l");
      await a.click("#copyLink");
      await sleep(300);
      const link = await a.evaluate(() => location.href);
      assert.match(link, /scene=s_[0-9a-f]+/);
      assert.match(link, /revision=\d+/);
      assert.match(link, /time=0\.8/);
      assert.match(link, /sel=elbow_l/);
      const s = await state(a);
      assert.notEqual(s.camera.yaw, 0);
      const hashA = await settledFrameHash(a);
      const urlA = await a.evaluate(() => window.dermisEditor.frameUrl());
      // Someone edits after the link was made: the link still shows its revision.
      await api("PATCH", `/scenes/${sceneId}/placements/elbow_l`, { h: 0.3 });
      const fresh = await browser.newContext();
      const c = await openEditor(fresh, link);
      const hashC = await settledFrameHash(c);
      assert.equal(await c.evaluate(() => window.dermisEditor.frameUrl()), urlA, "the same frame parameters");
      assert.equal(hashC, hashA);
      const sc = await state(c);
      assert.deepEqual(sc.selection, ["elbow_l"]);
      assert.equal(sc.pinnedRevision, s.revision);
      assert.ok(await c.$eval("#pinned", (e) => !e.hidden));
      await fresh.close();
    }],
    ["killing the event stream shows the offline banner; it clears on reconnect", async () => {
      const port = server.port, data = server.data;
      await server.kill();
      await a.waitForFunction(() => !document.getElementById("offline").hidden, null, { timeout: 10000 });
      await screenshot(a, "editor-offline.png");
      server = await startServer(exe, [], "dermis-editor-collab-", { port, data });
      // An edit made while A was away: A re-syncs when it is back.
      const edited = await api("PATCH", `/scenes/${sceneId}/placements/neck`, { h: 0.7 });
      assert.equal(edited.status, 200);
      await a.waitForFunction(() => document.getElementById("offline").hidden, null, { timeout: 20000 });
      await until(async () => (await state(a)).revision === edited.body.revision, "A re-synced", 10000);
    }],
    ["download the scene document", async () => {
      const [download] = await Promise.all([a.waitForEvent("download"), a.click("#download")]);
      const text = await (await download.createReadStream()).toArray();
      const saved = JSON.parse(Buffer.concat(text).toString("utf8"));
      assert.deepEqual(saved, (await api("GET", `/scenes/${sceneId}`)).body.scene);
      assert.match(download.suggestedFilename(), /^s_[0-9a-f]+-r\d+\.scene\.json$/);
    }],
    ["dropping a .glb makes a new scene on that model", async () => {
      const glb = readFileSync(new URL("../models/CesiumMan/CesiumMan.glb", import.meta.url));
      await a.evaluate(async (bytes) => {
        const dt = new DataTransfer();
        dt.items.add(new File([new Uint8Array(bytes)], "CesiumMan.glb", { type: "model/gltf-binary" }));
        document.body.dispatchEvent(new DragEvent("drop", { dataTransfer: dt, bubbles: true, cancelable: true }));
      }, [...glb]);
      await a.waitForFunction((first) => { const s = window.dermisEditor.store; return s.sceneId !== first && s.model && s.model.id !== "builtin:default"; }, sceneId, { timeout: 30000 });
      const s = await state(a);
      assert.equal(s.doc.placements.length, 0);
      assert.equal((await api("GET", `/scenes/${s.sceneId}`)).status, 200);
    }],
    ["Transfer from… another scene: the preview lists what comes over and what does not; Transfer applies it", async () => {
      const here = (await state(a)).sceneId;
      const preview = (await api("POST", `/scenes/${here}/transfer?apply=false`, { from: sceneId })).body;
      await a.click("#transferFrom");
      await a.selectOption("#transferSource", sceneId);
      await a.waitForFunction((n) => /come over/.test(document.getElementById("transferResult").textContent) && document.querySelectorAll("#transferList li").length === n, preview.transferred.length, { timeout: 10000 });
      assert.equal(await a.$$eval("#transferUnmapped li", (l) => l.length), preview.unmapped.length);
      await a.click("#transferGo");
      await a.waitForFunction((n) => document.getElementById("transferResult").textContent.includes(`Transferred ${n} in one revision`), preview.transferred.length, { timeout: 10000 });
      assert.equal((await api("GET", `/scenes/${here}`)).body.scene.placements.length, preview.transferred.length);
      await a.keyboard.press("Escape");
      // Onto a new scene of the default character every placement maps, with its id.
      const source = (await api("GET", `/scenes/${sceneId}`)).body.scene.placements;
      const empty = await api("POST", "/scenes", { format: "dermis.scene/1", model: "builtin:default", placements: [] });
      assert.equal(empty.status, 201);
      await a.goto(`${server.base}/?scene=${empty.body.id}`);
      await a.waitForFunction((id) => window.dermisEditor && window.dermisEditor.store.sceneId === id, empty.body.id, { timeout: 30000 });
      await a.click("#transferFrom");
      await a.selectOption("#transferSource", sceneId);
      await a.waitForFunction((n) => document.getElementById("transferGo").textContent === `Transfer ${n}`, source.length, { timeout: 10000 });
      await a.click("#transferGo");
      await a.waitForFunction((n) => document.getElementById("transferResult").textContent.includes(`Transferred ${n} in one revision`), source.length, { timeout: 10000 });
      const copied = (await api("GET", `/scenes/${empty.body.id}`)).body.scene.placements;
      assert.deepEqual(copied.map((p) => p.id), source.map((p) => p.id));
      await a.keyboard.press("Escape");
    }],
    ["two changes by someone else in quick succession: a late answer to the first read does not take the editor back", async () => {
      // Each change event starts a read of the scene; here the first read's answer (the older
      // revision) is held back until after the second one's. The editor must end at the newest.
      const path = new URL(`${server.base}/api/v1/scenes/${sceneId}`).pathname;
      const reads = await holdAnswers(b, (url) => url.pathname === path, { methods: ["GET"], first: 1 }); // read now (the older revision), delivered late
      const d = (await api("GET", `/scenes/${sceneId}`)).body;
      let r = d.revision;
      for (const id of ["neck", "stomach"]) {
        const p = d.scene.placements.find((q) => q.id === id);
        const answer = await api("PATCH", `/scenes/${sceneId}/placements/${id}`, { h: p.h > 0.5 ? p.h - 0.1 : p.h + 0.1 });
        assert.equal(answer.status, 200);
        r = answer.body.revision;
        await sleep(150); // the first event's read is on its way before the second change
      }
      await until(async () => reads.seen >= 2, "two reads");
      await until(() => reads.delivered >= 1, "the held answer delivered", 30000);
      await reads.stop();
      await until(async () => (await state(b)).revision === r, `the editor at the newest revision (${r})`);
      await sleep(300); // and it stays there
      const s = await state(b);
      assert.equal(s.revision, r, `the editor is at the newest revision (${s.revision}, server ${r}, reads ${reads.seen})`);
      assert.deepEqual(s.doc, (await api("GET", `/scenes/${sceneId}`)).body.scene);
    }],
    ["changes whose answers are slow stay with their scene, and add up (every PATCH, PUT and DELETE answer held 1 s)", async () => {
      // A person on a slow link: each edit's answer arrives a second after the server has it.
      const s1 = (await api("POST", "/scenes", { default_patterns: true })).body.id;
      const s2 = (await api("POST", "/scenes", { default_patterns: true })).body.id;
      const c = await openEditor(await browser.newContext(), `${server.base}/?scene=${s1}`);
      await holdAnswers(c, (url) => url.pathname.startsWith("/api/v1/scenes/"), { methods: ["PATCH", "PUT", "DELETE"] });
      const scene = async (id) => (await api("GET", `/scenes/${id}`)).body;
      const placement = async (id, pid) => (await scene(id)).scene.placements.find((p) => p.id === pid);
      await select(c, "neck");
      // `]` then D at once: the copy has the rotation the window shows (the burst's), not the stored one.
      const neck0 = await placement(s1, "neck");
      await c.keyboard.press("]");
      await c.keyboard.press("d");
      const copy = await until(async () => { const d = (await scene(s1)).scene; return d.placements.length === 19 && d.placements[18]; }, "the copy on the server");
      const neck1 = await placement(s1, "neck");
      assert.notEqual(neck1.rotation, neck0.rotation, "the burst turned the neck");
      assert.equal(copy.rotation, neck1.rotation, "the copy is turned as the neck was shown");
      // Alt+↓ twice within one answer's time: the row moves two places.
      await until(async () => (await state(c)).revision === (await scene(s1)).revision && !(await c.evaluate(() => window.dermisEditor.store.busy)), "the window settled");
      const ids0 = (await scene(s1)).scene.placements.map((p) => p.id);
      await c.focus(`#placementList li[data-placement="${ids0[0]}"] .name`);
      await c.keyboard.press("Alt+ArrowDown");
      // The first move's re-render comes between the presses (the list shows it one place down).
      await until(() => c.evaluate((id) => [...document.querySelectorAll("#placementList li")].findIndex((li) => li.dataset.placement === id) === 1, ids0[0]), "the list re-rendered with the first move");
      await c.keyboard.press("Alt+ArrowDown");
      const ids1 = await until(async () => { const ids = (await scene(s1)).scene.placements.map((p) => p.id); return ids[2] === ids0[0] && ids; }, "moved down two places");
      assert.deepEqual(ids1.slice(0, 2), ids0.slice(1, 3));
      // A key burst still waiting when another scene is opened goes to the scene it was made in.
      await until(async () => !(await c.evaluate(() => window.dermisEditor.store.busy)), "the window settled");
      const before2 = await scene(s2);
      await select(c, "neck");
      const neckBefore = await placement(s1, "neck");
      await c.keyboard.press("]");
      await c.selectOption("#scene", s2);
      await until(async () => (await state(c)).sceneId === s2, "the other scene open");
      const neckAfter = await until(async () => { const p = await placement(s1, "neck"); return p.rotation !== neckBefore.rotation && p; }, "the burst on the first scene");
      assert.ok(Math.abs((((neckAfter.rotation - neckBefore.rotation) % 360) + 360) % 360 - 5) < 1e-6, `turned once, on its own scene (${neckBefore.rotation} → ${neckAfter.rotation})`);
      assert.deepEqual(await scene(s2), before2, "the other scene is untouched");
      // Its undo steps stayed behind: Ctrl+Z here has nothing to undo.
      await c.focus("#uv");
      await c.keyboard.press("Control+z");
      await c.waitForSelector('#notices .notice:has-text("Nothing to undo")', { timeout: 15000 });
      assert.equal((await scene(s2)).revision, before2.revision);
      // A deletion's Undo notice, clicked after another scene was opened, does not touch that scene.
      await c.selectOption("#scene", s1);
      await until(async () => (await state(c)).sceneId === s1, "back on the first scene");
      await select(c, "knee_l");
      await c.keyboard.press("Delete");
      const undoButton = await c.waitForSelector('#notices .notice:has-text("Deleted \\"knee_l\\"") button.action', { timeout: 10000 });
      await until(async () => !(await placement(s1, "knee_l")), "knee_l deleted");
      await c.selectOption("#scene", s2);
      await until(async () => (await state(c)).sceneId === s2, "the other scene open again");
      await undoButton.click();
      await c.waitForSelector('#notices .notice:has-text("deletion was in another scene")', { timeout: 15000 });
      await sleep(1500);
      assert.deepEqual(await scene(s2), before2, "the other scene is still untouched");
      assert.deepEqual(c.errors, []);
      await c.close();
    }],
    ["comparing against a revision, then opening another scene: the comparison is against patterns off there", async () => {
      // A revision number is one scene's: the other scene's r1 is another picture.
      const s1 = (await api("POST", "/scenes", { default_patterns: true })).body.id;
      const s2 = (await api("POST", "/scenes", { default_patterns: true })).body.id;
      const p0 = (await api("GET", `/scenes/${s1}`)).body.scene.placements[0];
      assert.equal((await api("PATCH", `/scenes/${s1}/placements/${p0.id}`, { h: p0.h / 2 })).status, 200);
      const c = await openEditor(await browser.newContext(), `${server.base}/?scene=${s1}`);
      await c.selectOption("#compareMode", "diff");
      const shown = (await state(c)).revision;
      const r1 = String((await api("GET", `/scenes/${s1}/revisions`)).body.revisions.find((r) => r.revision !== shown).revision);
      await c.waitForSelector(`#compareAgainst option[value="${r1}"]`, { state: "attached", timeout: 10000 });
      // Listen before choosing: the change handler may send the diff before selectOption returns.
      const diffs = [];
      c.on("request", (r) => { if (r.url().includes("/frame-diff")) diffs.push(new URL(r.url())); });
      await c.selectOption("#compareAgainst", r1);
      await until(async () => diffs.some((u) => u.searchParams.get("against") === r1), "a diff against that revision");
      diffs.length = 0;
      await c.selectOption("#scene", s2);
      await until(async () => (await state(c)).sceneId === s2, "the other scene open");
      await until(async () => diffs.some((u) => u.pathname.includes(s2)), "a diff of the other scene");
      assert.equal(await c.evaluate(() => window.dermisEditor.store.compare.against), "off");
      assert.equal(await c.$eval("#compareAgainst", (e) => e.value), "off");
      for (const u of diffs.filter((x) => x.pathname.includes(s2))) assert.equal(u.searchParams.get("against"), "off", `${u}`);
      assert.deepEqual(c.errors, []);
      await c.close();
    }],
    ["no script errors", async () => { assert.deepEqual(a.errors, []); assert.deepEqual(b.errors, []); }],
  ]);
  return failures;
}, async () => {
  await browser.close();
  server.stop();
});
