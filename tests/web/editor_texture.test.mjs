// WebEditorTextureBrowserTest — the editor's texture view and keys in Debian's Chromium
// (playwright-core) against a real dermis-server on 127.0.0.1 with a fresh data folder.
// Usage: node editor_texture.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: one outline per placement and a decoded frame; dragging a footprint moves it (server
// within one texel) and changes the frame; a 2 s drag sends one edit and ends where the
// pointer stopped; Shift-rotate snaps to 15°; Esc cancels (server unchanged); a number key
// places a pattern; nudge / rotate / scale keys; an undo while a drag's or a key burst's edit is
// still on its way undoes that edit only; Delete, undo, redo; a history click reverts; the
// history list is one Tab stop (arrows / Home / End move, Enter reverts);
// H sends enabled:false and zeroes that region of the bump map; S solos; M mirrors.
import assert from "node:assert/strict";
import { startServer, launch, apiClient, openEditor, waitFrame, settledFrameHash, state, footprint, screenshot,
         runChecks, runSuite, settled, countEdits, until, sleep, selectPlacement, holdAnswers } from "./editor_lib.mjs";

const server = await startServer(process.argv[2], [], "dermis-editor-tex-");
const api = apiClient(server.base);
const browser = await launch();
await runSuite("WebEditorTextureBrowserTest", async () => {
  const context = await browser.newContext();
  const page = await openEditor(context, server.base + "/");
  const edits = countEdits(page);
  const sceneId = (await state(page)).sceneId;
  const serverPlacement = async (id) => (await api("GET", `/scenes/${sceneId}`)).body.scene.placements.find((p) => p.id === id);
  const texel = 1 / 1024;
  const select = async (id) => {
    await selectPlacement(page, id);
    await page.focus("#uv");
  };
  const settle = () => settled(page, api);

  let failures = await runChecks("WebEditorTextureBrowserTest", [
    ["one outline per placement and a decoded frame", async () => {
      const s = await state(page);
      assert.ok(s.doc.placements.length >= 10);
      const rows = await page.$$eval("#placementList li", (l) => l.length);
      assert.equal(rows, s.doc.placements.length);
      const box = await page.$eval("#uv", (c) => { const r = c.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; });
      for (const p of s.doc.placements) {
        const g = await footprint(page, p.id);
        assert.ok(g, `footprint of ${p.id}`);
        for (const [x, y] of g.corners) assert.ok(x >= box[0] && x <= box[2] && y >= box[1] && y <= box[3], `${p.id} on the canvas`);
        // The outline is drawn: a bright pixel near the middle of its top edge.
        const mid = [(g.corners[0][0] + g.corners[1][0]) / 2, (g.corners[0][1] + g.corners[1][1]) / 2];
        const lit = await page.evaluate(([x, y]) => {
          const c = document.getElementById("uv"), r = c.getBoundingClientRect(), k = c.width / r.width;
          const d = c.getContext("2d").getImageData(Math.round((x - r.left) * k) - 2, Math.round((y - r.top) * k) - 2, 5, 5).data;
          let best = 0;
          for (let i = 0; i < d.length; i += 4) best = Math.max(best, d[i] + d[i + 1] + d[i + 2]);
          return best;
        }, mid);
        assert.ok(lit > 350, `outline of ${p.id} drawn (brightness ${lit})`);
      }
      assert.ok(await page.$eval("#frame", (i) => i.naturalWidth === 512 && i.naturalHeight === 512));
      await screenshot(page, "editor-both.png");
    }],
    ["dragging a footprint moves the placement and changes the frame", async () => {
      const before = await serverPlacement("stomach");
      const hash0 = await settledFrameHash(page);
      const g = await footprint(page, "stomach");
      await page.mouse.move(g.center[0], g.center[1]);
      await page.mouse.down();
      for (let i = 1; i <= 8; ++i) { await page.mouse.move(g.center[0] + 5 * i, g.center[1] + 2 * i); await sleep(30); }
      await page.mouse.up();
      const want = [before.center[0] + 40 / g.pxPerUV, before.center[1] + 16 / g.pxPerUV];
      const after = await until(async () => {
        const p = await serverPlacement("stomach");
        return Math.abs(p.center[0] - want[0]) <= texel && Math.abs(p.center[1] - want[1]) <= texel && p;
      }, "the server's placement where the pointer stopped");
      assert.ok(after);
      await settle();
      const hash1 = await settledFrameHash(page);
      assert.notEqual(hash1, hash0, "the frame changed");
    }],
    ["a 2 s drag sends one edit, when it ends, where the pointer stopped", async () => {
      await settle();
      const before = await serverPlacement("neck");
      const g = await footprint(page, "neck");
      edits.length = 0;
      // Pointer events at 60 Hz for 2 s, dispatched in the page (the browser's own timing).
      const { moves, last } = await page.evaluate(([x0, y0]) => new Promise((resolve) => {
        const c = document.getElementById("uv");
        const ev = (type, x, y) => c.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, button: 0, buttons: type === "pointerup" ? 0 : 1, pointerId: 7, bubbles: true }));
        ev("pointerdown", x0, y0);
        const t0 = performance.now();
        let i = 0, at = [x0, y0];
        const timer = setInterval(() => {
          ++i;
          at = [x0 + (i % 40), y0 + (Math.floor(i / 4) % 20)];
          ev("pointermove", at[0], at[1]);
          if (i >= 60 && performance.now() - t0 >= 2000) { // both: page timers slip on a loaded machine
            clearInterval(timer);
            ev("pointerup", at[0], at[1]);
            resolve({ moves: i, last: at });
          }
        }, 1000 / 60);
      }), g.center);
      const i = moves;
      await settle();
      await sleep(300);
      const sent = edits.filter((e) => e.path.endsWith("/placements/neck")).length;
      assert.ok(i >= 45, `${i} pointer moves`);
      await until(async () => !(await page.evaluate(() => window.dermisEditor.store.busy)), "idle");
      assert.equal(sent, 1, `one edit for the whole gesture (${sent} edits for ${i} moves)`);
      const p = await serverPlacement("neck");
      const want = [before.center[0] + (last[0] - g.center[0]) / g.pxPerUV, before.center[1] + (last[1] - g.center[1]) / g.pxPerUV];
      assert.ok(Math.abs(p.center[0] - want[0]) <= texel && Math.abs(p.center[1] - want[1]) <= texel, `${p.center} vs ${want}`);
    }],
    ["Shift-rotate snaps to 15°", async () => {
      await select("thigh_l");
      const g = await footprint(page, "thigh_l");
      await page.mouse.move(g.rotate[0], g.rotate[1]);
      await page.mouse.down();
      await page.keyboard.down("Shift");
      // 37° clockwise from straight up about the centre.
      const r = Math.hypot(g.rotate[0] - g.center[0], g.rotate[1] - g.center[1]);
      const a = (37 * Math.PI) / 180;
      await page.mouse.move(g.center[0] + r * Math.sin(a), g.center[1] - r * Math.cos(a), { steps: 6 });
      await page.mouse.up();
      await page.keyboard.up("Shift");
      await settle();
      const p = await serverPlacement("thigh_l");
      assert.equal(p.rotation % 15, 0, `rotation ${p.rotation}`);
      assert.ok(Math.abs(p.rotation - 37) <= 8, `rotation ${p.rotation} near 37`);
    }],
    ["Esc during a drag restores the placement", async () => {
      await settle();
      const before = await serverPlacement("knee_l");
      const revBefore = (await state(page)).revision;
      const g = await footprint(page, "knee_l");
      // A quick drag cancelled before any edit left: the placement is restored and nothing is sent.
      edits.length = 0;
      const during = await page.evaluate(([x0, y0]) => {
        const c = document.getElementById("uv");
        const ev = (type, x, y) => c.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, button: 0, buttons: 1, pointerId: 8, bubbles: true }));
        ev("pointerdown", x0, y0);
        ev("pointermove", x0 + 30, y0 + 10);
        const moved = window.dermisEditor.screenGeometry("knee_l").center;
        document.dispatchEvent(new KeyboardEvent("keydown", { key: "Escape", bubbles: true }));
        ev("pointerup", x0 + 30, y0 + 10);
        return { moved, after: window.dermisEditor.screenGeometry("knee_l").center };
      }, g.center);
      assert.ok(Math.abs(during.moved[0] - g.center[0] - 30) < 1, "the footprint followed the pointer");
      assert.ok(Math.abs(during.after[0] - g.center[0]) < 1e-6, "Esc put it back");
      await sleep(400);
      assert.equal(edits.filter((e) => e.path.includes("/placements/knee_l")).length, 0, "a cancelled quick drag sends nothing");
      // A long drag cancelled after edits left: the scene goes back to the revision before it.
      await page.mouse.move(g.center[0], g.center[1]);
      await page.mouse.down();
      for (let i = 1; i <= 10; ++i) { await page.mouse.move(g.center[0] + 4 * i, g.center[1] + 3 * i); await sleep(40); }
      await page.keyboard.press("Escape");
      await page.mouse.up();
      await settle();
      const after = await serverPlacement("knee_l");
      assert.deepEqual(after, before);
      assert.deepEqual((await api("GET", `/scenes/${sceneId}`)).body.scene.placements.find((p) => p.id === "knee_l"), before);
      const s = await state(page);
      assert.ok(s.revision >= revBefore);
      assert.deepEqual(s.doc.placements.find((p) => p.id === "knee_l"), before);
    }],
    ["a number key places the library's pattern at the pointer", async () => {
      await settle();
      const n0 = (await state(page)).doc.placements.length;
      const patterns = (await api("GET", "/patterns")).body.patterns;
      const g = await footprint(page, "stomach");
      // A point of the torso chart just below the stomach footprint.
      const at = [g.center[0], g.center[1] + 0.09 * g.pxPerUV];
      await page.mouse.move(at[0], at[1]);
      await page.keyboard.press("2");
      const s = await until(async () => { const t = await state(page); return t.doc.placements.length === n0 + 1 && t; }, "one more placement");
      const added = s.doc.placements[s.doc.placements.length - 1];
      assert.equal(added.pattern, patterns[1].id);
      const uv = await page.evaluate(([x, y]) => window.dermisEditor.screenGeometry("stomach").uvAt(x, y), at);
      assert.ok(Math.abs(added.center[0] - uv[0]) < 0.002 && Math.abs(added.center[1] - uv[1]) < 0.002, `${added.center} vs ${uv}`);
      assert.deepEqual(s.selection, [added.id]);
      assert.ok(["spine_01", "spine_02", "spine_03", "pelvis"].includes(added.joint), `suggested driver ${added.joint}`);
    }],
    ["nudge, rotate and scale keys", async () => {
      await select("elbow_l");
      const p0 = await serverPlacement("elbow_l");
      await page.keyboard.press("ArrowRight");
      await page.keyboard.press("Shift+ArrowDown");
      await until(async () => { const p = await serverPlacement("elbow_l"); return Math.abs(p.center[1] - p0.center[1] - 10 * texel) < 2e-4; }, "nudged down");
      await page.keyboard.press("]");
      await until(async () => (await serverPlacement("elbow_l")).rotation === p0.rotation + 5, "rotated by 5");
      await page.keyboard.press("+");
      const p = await until(async () => { const q = await serverPlacement("elbow_l"); return q.scale[0] > p0.scale[0] && q; }, "scaled up");
      assert.ok(Math.abs(p.center[0] - p0.center[0] - texel) < 2e-4, `nudged right: ${p.center[0]} vs ${p0.center[0]}`);
      assert.ok(Math.abs(p.scale[0] / p0.scale[0] - 1.05) < 0.01 && Math.abs(p.scale[1] / p0.scale[1] - 1.05) < 0.01);
    }],
    ["an undo pressed while a drag's or a key burst's edit is on its way undoes that edit, not the one before", async () => {
      await settle();
      const scene = async () => (await api("GET", `/scenes/${sceneId}`)).body.scene;
      // Every PATCH answer comes back 1.5 s late (the server has applied it by then).
      const late = (url) => url.pathname.startsWith(`/api/v1/scenes/${sceneId}/placements/`);
      const lateAnswers = await holdAnswers(page, late, { methods: ["PATCH"], ms: 1500 });
      try {
        const before = await scene();
        const p0 = before.placements.find((p) => p.id === "stomach");
        const g = await footprint(page, "stomach");
        await page.mouse.move(g.center[0], g.center[1]);
        await page.mouse.down();
        for (let i = 1; i <= 4; ++i) { await page.mouse.move(g.center[0] + 6 * i, g.center[1]); await sleep(30); }
        await page.mouse.up();
        await until(async () => (await serverPlacement("stomach")).center[0] > p0.center[0] + 2 * texel, "the drag on the server");
        await page.keyboard.press("Control+z"); // the drag's answer is still on its way
        await until(async () => JSON.stringify(await scene()) === JSON.stringify(before), "undo takes back the drag and nothing else");
        await settle();
        assert.deepEqual(await scene(), before, "and no earlier edit went with it");
        // A key burst: `]` commits after a pause; Ctrl+Z as soon as the server has it.
        await select("stomach");
        await page.keyboard.press("]");
        await until(async () => (await serverPlacement("stomach")).rotation === p0.rotation + 5, "the burst on the server");
        await page.keyboard.press("Control+z");
        await until(async () => JSON.stringify(await scene()) === JSON.stringify(before), "undo takes back the burst and nothing else");
        await settle();
        assert.deepEqual(await scene(), before, "and no earlier edit went with it");
      } finally {
        await lateAnswers.stop();
      }
    }],
    ["Delete, then undo restores it and redo removes it again (server state)", async () => {
      await settle();
      await select("clavicle_l");
      const before = await serverPlacement("clavicle_l");
      await page.keyboard.press("Delete");
      await until(async () => !(await serverPlacement("clavicle_l")), "deleted on the server");
      await settle();
      await page.keyboard.press("Control+z");
      const back = await until(() => serverPlacement("clavicle_l"), "restored by undo");
      assert.deepEqual(back, before);
      await settle();
      await page.keyboard.press("Control+Shift+z");
      await until(async () => !(await serverPlacement("clavicle_l")), "removed again by redo");
      await settle();
      await page.click("#undo");
      await until(() => serverPlacement("clavicle_l"), "restored by the Undo button");
    }],
    ["a history click reverts to that revision", async () => {
      await settle();
      const revisions = (await api("GET", `/scenes/${sceneId}/revisions?limit=10`)).body.revisions;
      const target = revisions[3].revision;
      const want = (await api("GET", `/scenes/${sceneId}?revision=${target}`)).body.scene;
      await page.click(`#historyList li[data-revision="${target}"] button`);
      await until(async () => JSON.stringify((await api("GET", `/scenes/${sceneId}`)).body.scene) === JSON.stringify(want), "the scene equals the clicked revision");
      await settle();
      assert.deepEqual((await state(page)).doc, want);
    }],
    ["the history list is one Tab stop: arrows, Home and End move, Enter reverts", async () => {
      await settle();
      const revisions = (await api("GET", `/scenes/${sceneId}/revisions?limit=10`)).body.revisions;
      const rev0 = (await state(page)).revision;
      const stops = () => page.$$eval('#historyList [tabindex="0"]', (b) => b.map((e) => e.closest("li").dataset.revision));
      // The list reloads once things are quiet (200 ms, then a read): wait until it is current.
      await until(() => page.$eval("#historyList li", (li) => li.dataset.revision).then((r) => r === String(revisions[0].revision)), "the history list is current");
      await until(async () => (await stops()).length === 1, "one tab stop in the history list");
      assert.ok(await page.$$eval("#historyList button", (b) => b.length) > 3);
      await page.focus('#historyList [tabindex="0"]');
      const focused = () => page.evaluate(() => document.activeElement.closest("#historyList li")?.dataset.revision);
      await page.keyboard.press("Home");
      assert.equal(await focused(), String(revisions[0].revision), "Home: the newest");
      await page.keyboard.press("ArrowDown");
      await page.keyboard.press("ArrowDown");
      assert.equal(await focused(), String(revisions[2].revision), "↓↓ moves two revisions back");
      assert.deepEqual(await stops(), [String(revisions[2].revision)], "the tab stop follows the focus");
      await page.keyboard.press("ArrowUp");
      assert.equal(await focused(), String(revisions[1].revision), "↑ moves one forward");
      await page.keyboard.press("End");
      assert.equal(await focused(), await page.$eval("#historyList li:last-child", (li) => li.dataset.revision), "End: the oldest listed");
      await page.keyboard.press("Home");
      assert.equal(await focused(), String(revisions[0].revision), "Home: the newest");
      assert.equal((await state(page)).revision, rev0, "moving reverts nothing");
      // Tab leaves the list at once.
      await page.keyboard.press("Tab");
      assert.equal(await page.evaluate(() => !!document.activeElement.closest("#historyList")), false, "one Tab leaves the list");
      await page.keyboard.press("Shift+Tab");
      assert.equal(await focused(), String(revisions[0].revision), "Shift+Tab comes back to the same row");
      const target = revisions[2].revision;
      const want = (await api("GET", `/scenes/${sceneId}?revision=${target}`)).body.scene;
      await page.keyboard.press("ArrowDown");
      await page.keyboard.press("ArrowDown");
      await page.keyboard.press("Enter");
      await until(async () => JSON.stringify((await api("GET", `/scenes/${sceneId}`)).body.scene) === JSON.stringify(want), "Enter reverts to the focused revision");
      await settle();
      assert.ok(await page.evaluate(() => !!document.activeElement.closest("#historyList")), "the focus stays in the history list after the reload");
    }],
    ["H hides: enabled false, and that region of the bump map becomes 0", async () => {
      await settle();
      // Pose the left elbow at the crease's θmax so that it shows, through the parameters panel.
      await select("elbow_l");
      const thetaMax = (await serverPlacement("elbow_l")).theta_max;
      await page.click("#goMax");
      await until(async () => { const j = (await api("GET", `/scenes/${sceneId}`)).body.scene.pose.joints["forearm.l"]; return j && j.axis_angles && j.axis_angles.x === thetaMax; }, "posed at θmax");
      await settle();
      const p = await serverPlacement("elbow_l");
      const probe = async () => (await api("GET", `/scenes/${sceneId}/probe?u=${p.center[0]}&v=${p.center[1]}`)).body;
      const shown = await probe();
      assert.ok(shown.contributions.some((c) => c.placement === "elbow_l" && c.t > 0.99), JSON.stringify(shown.contributions));
      assert.notEqual(shown.bump, 0);
      await page.focus("#uv");
      await page.keyboard.press("h");
      await until(async () => (await serverPlacement("elbow_l")).enabled === false, "enabled: false on the server");
      const hidden = await probe();
      assert.equal(hidden.contributions.filter((c) => c.placement === "elbow_l").length, 0);
      assert.equal(hidden.bump, 0);
      await page.keyboard.press("h");
      await until(async () => (await serverPlacement("elbow_l")).enabled === true, "shown again");
    }],
    ["S solos the selection in the 3D view", async () => {
      await settle();
      await select("elbow_l");
      const hash0 = await settledFrameHash(page);
      await page.keyboard.press("s");
      await until(async () => (await state(page)).solo.includes("elbow_l"), "solo in the state");
      await until(() => page.$eval("#frame", (i) => (i.dataset.url || "").includes("only=elbow_l")), "the frame shows only elbow_l");
      const hash1 = await settledFrameHash(page);
      assert.notEqual(hash1, hash0);
      await page.keyboard.press("s");
      await until(async () => (await state(page)).solo.length === 0, "solo off");
    }],
    ["M mirrors: the twin appears with the mirrored joint", async () => {
      // The default set has the twin already (a second mirror would be 409): remove it first.
      await api("DELETE", `/scenes/${sceneId}/placements/elbow_r`);
      await until(async () => !(await state(page)).doc.placements.some((q) => q.id === "elbow_r"), "the editor heard of the delete");
      await settle();
      await select("elbow_l");
      const n0 = (await api("GET", `/scenes/${sceneId}`)).body.scene.placements.length;
      await page.keyboard.press("m");
      const doc = await until(async () => { const d = (await api("GET", `/scenes/${sceneId}`)).body.scene; return d.placements.length === n0 + 1 && d; }, "one more placement");
      const twin = doc.placements[doc.placements.length - 1];
      const left = doc.placements.find((q) => q.id === "elbow_l");
      assert.equal(twin.joint, left.joint.replace(/\.l$/, ".r"));
      assert.ok(twin.center[0] !== left.center[0]);
      // M again: the twin is there; the notice asks to bring it up to date instead of stacking a
      // second one (POST …/mirror?update=true).
      await settle();
      const r0 = (await api("GET", `/scenes/${sceneId}`)).body.revision;
      await page.keyboard.press("m");
      const ask = await until(async () => {
        for (const b of await page.$$("#notices .notice button")) if ((await b.textContent()) === "Update twin") return b;
        return null;
      }, "the notice asks whether to update the twin");
      await ask.click();
      const updated = await until(async () => { const d = (await api("GET", `/scenes/${sceneId}`)).body; return d.revision > r0 && d; }, "the twin brought up to date");
      assert.equal(updated.scene.placements.length, n0 + 1, "no second twin");
      assert.ok(updated.scene.placements.some((q) => q.id === twin.id), "the twin keeps its id");
      await settle();
      await screenshot(page, "editor-texture-mirror.png");
      // Texture view alone (Tab from the texture view switches to 3D when one view is shown).
      await page.click('[data-layout="texture"]');
      // The notices of earlier checks (Deleted…, Undone…) are dismissed, as a person would, for a
      // clean picture (docs/editor-texture.png is a copy of it).
      for (const close of await page.$$('#notices .notice button[aria-label="dismiss"]')) await close.click();
      await sleep(300);
      await screenshot(page, "editor-texture.png");
      await page.focus("#uv");
      await page.keyboard.press("Tab");
      await until(() => page.$eval(".workspace", (w) => w.dataset.layout === "3d"), "Tab switched to the 3D view");
      await waitFrame(page);
      await screenshot(page, "editor-3d.png");
      // A second Tab moves on (no trap): the layout stays, the focus leaves the view.
      await page.keyboard.press("Tab");
      await sleep(100);
      assert.equal(await page.$eval(".workspace", (w) => w.dataset.layout), "3d", "the second Tab does not switch back");
      assert.equal(await page.evaluate(() => !!document.activeElement.closest(".view")), false, "the second Tab leaves the views");
      await page.click('[data-layout="both"]');
    }],
    ["no script errors", async () => assert.deepEqual(page.errors, [])],
  ]);
  return failures;
}, async () => {
  await browser.close();
  server.stop();
});
