// WebEditorSurfaceBrowserTest — placements on the body (SPEC §8, issue #22 item 4) in the editor, in
// Debian's Chromium (playwright-core) against a real dermis-server on 127.0.0.1, on a character the
// other suites never use: the KayKit Barbarian (a palette atlas: its maps live in the generated
// layout).
// Usage: node editor_surface.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the place tool's brush is a circle on the body (`surface_brush` with the brush's diameter;
// ] and [ size it); a click adds a surface placement at the pick's anchor with the suggested driver
// and a decal the brush wide, selected and outlined on the skin; the texture view draws its
// outline in the generated layout (every piece) with its anchor, selects it by a click there, and
// a drag there slides it over the body (anchor moved, one undo step that puts it back); + and ]
// scale its size in model units and turn it; three quick arrows move it three texels over the body (each
// answer held back 1 s); the parameters panel shows size and depth; in the 3D
// view a drag that starts on the selected decal moves it (anchor changed, camera not turned);
// "Place as: in the texture" adds a UV placement instead; after Propose…'s set on the body, every
// surface placement's label is laid out with the others and none overlaps another.
// Screenshots: editor-surface-brush.png, editor-surface-placed.png, editor-surface-texture.png,
// editor-surface-labels.png.
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { startServer, launch, apiClient, openEditor, state, screenshot, runChecks, runSuite, until, sleep, settledFrameHash, holdAnswers } from "./editor_lib.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const barbarian = join(here, "../models/KayKitBarbarian/Barbarian.glb");

const server = await startServer(process.argv[2], [], "dermis-editor-surface-");
const api = apiClient(server.base);
const browser = await launch();

await runSuite("WebEditorSurfaceBrowserTest", async () => {
  const up = await fetch(`${server.base}/api/v1/models?name=barbarian`, { method: "POST", headers: { "Content-Type": "model/gltf-binary" }, body: readFileSync(barbarian) });
  assert.ok(up.status === 201 || up.status === 200, `model upload: ${up.status}`);
  const modelId = (await up.json()).id;
  const created = await api("POST", "/scenes", { format: "dermis.scene/1", model: modelId, placements: [] });
  assert.equal(created.status, 201, JSON.stringify(created.body));
  const sceneId = created.body.id;
  const context = await browser.newContext();
  const page = await openEditor(context, `${server.base}/?scene=${sceneId}`, { width: 1600, height: 1000 });
  const frameUrl = () => page.evaluate(() => window.dermisEditor.frameUrl());
  const param = async (name) => new URL("http://x/api/v1" + await frameUrl()).searchParams.get(name);
  const doc = async () => (await api("GET", `/scenes/${sceneId}`)).body.scene;
  const frameBox = async () => {
    const b = await page.$eval("#frame", (i) => { const r = i.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
    const side = Math.min(b[2], b[3]);
    return { x0: b[0] + (b[2] - side) / 2, y0: b[1] + (b[3] - side) / 2, side };
  };
  const frameSize = () => page.evaluate(async () => (await import("/js/frame_view.js")).frameParams().width);
  const client = async (px) => { const b = await frameBox(), n = await frameSize(); return [b.x0 + (px[0] + 0.5) / n * b.side, b.y0 + (px[1] + 0.5) / n * b.side]; };
  const near = (a, b, tol) => a.every((x, i) => Math.abs(x - b[i]) <= tol);
  let px = null, pick = null, placedId = null;

  const failures = await runChecks("WebEditorSurfaceBrowserTest", [
    ["the place tool's brush is a circle on the body, sized by ] and [", async () => {
      assert.equal(await page.evaluate(() => window.dermisEditor.store.layout.layout), "generated", "the Barbarian's maps live in the generated layout");
      // A frame pixel on the torso (the editor's own pick).
      const found = await page.evaluate(async () => {
        for (const y of [0.45, 0.5, 0.4, 0.55])
          for (const x of [0.5, 0.47, 0.53]) {
            const n = 512, hit = await window.dermisEditor.pickAt(Math.floor(n * x), Math.floor(n * y));
            if (hit.hit && hit.anchor) return { px: [Math.floor(n * x), Math.floor(n * y)], hit };
          }
        return null;
      });
      assert.ok(found, "a pixel on the body");
      px = found.px;
      pick = found.hit;
      await page.click("#placeTool");
      const [x, y] = await client(px);
      await page.mouse.move(x - 3, y);
      await page.mouse.move(x, y);
      // The brush sits at the body point under the pointer (the view's last hover pick there).
      // Waits for the pick of the pointer's last pixel (an earlier one may still be answered).
      const lastPick = () => page.evaluate(async () => { const l = (await import("/js/camera3d.js")).pointer.last; return l && l.hit && { px: l.px, anchor: l.hit.anchor }; });
      const settledBrush = await until(async () => {
        const u = await lastPick(), b = await param("surface_brush");
        return b && u && Math.abs(u.px[0] - px[0]) <= 1 && Math.abs(u.px[1] - px[1]) <= 1 && near(b.split(",").map(Number).slice(0, 3), u.anchor.position, 1e-4) && { b: b.split(",").map(Number), u: u.anchor };
      }, "a surface brush at the pointer's pixel in the frame URL");
      const brush = settledBrush.b, under = settledBrush.u;
      assert.equal(brush.length, 7);
      assert.ok(near(brush.slice(0, 3), under.position, 1e-4), `${brush} vs ${under.position}`);
      assert.ok(near(brush.slice(3, 6), under.normal, 1e-4), `${brush} vs ${under.normal}`);
      assert.ok(near(under.position, pick.anchor.position, 0.1), "near the pixel the test picked");
      assert.ok(brush[6] > 0);
      assert.equal(await param("brush"), null, "no UV brush");
      await page.focus("#frameStage");
      await page.keyboard.press("]");
      const bigger = await until(async () => { const b = (await param("surface_brush")).split(",").map(Number)[6]; return b > brush[6] && b; }, "a larger brush");
      assert.ok(Math.abs(bigger / brush[6] - 1.25) < 0.06, `${bigger} / ${brush[6]}`);
      assert.match(await page.$eval("#placeHint", (e) => e.textContent), /on the body, [\d.]+ units wide/);
      await settledFrameHash(page);
      await screenshot(page, "editor-surface-brush.png");
    }],
    ["a click adds a surface placement there: anchor, suggested driver, the brush's size; selected and outlined", async () => {
      const diameter = Number((await param("surface_brush")).split(",")[6]);
      const n0 = (await doc()).placements.length;
      const [x, y] = await client(px);
      await page.mouse.click(x, y);
      const d = await until(async () => { const s = await doc(); return s.placements.length === n0 + 1 && s; }, "a new placement");
      const p = d.placements[d.placements.length - 1];
      placedId = p.id;
      assert.equal(p.projection, "surface");
      const under = await page.evaluate(async () => (await import("/js/camera3d.js")).pointer.last.hit.anchor);
      assert.ok(near(p.anchor.position, under.position, 1e-5), `${p.anchor.position} vs ${under.position}`);
      assert.ok(near(p.anchor.normal, under.normal, 1e-5));
      assert.deepEqual(p.size, [diameter, diameter]);
      assert.equal(p.joint, pick.suggested.joint);
      await until(async () => (await state(page)).selection.join() === p.id, "the new placement selected");
      await page.keyboard.press("p"); // leave the place tool
      await until(async () => (await param("highlight")) === p.id, "highlight in the frame");
      assert.equal(await param("surface_brush"), null, "no brush once the tool is off");
      await settledFrameHash(page);
      await screenshot(page, "editor-surface-placed.png");
      assert.ok(await page.$("#pDepth"), "the parameters panel shows the depth");
      assert.equal(await page.$("#pU"), null, "and no UV centre");
    }],
    ["the texture view draws its outline in the generated layout, selects it and slides it over the body", async () => {
      const g = await until(() => page.evaluate((id) => { const s = window.dermisEditor.screenGeometry(id); return s && { center: s.center, bounds: s.bounds, segments: s.segments }; }, placedId), "its outline in the texture view");
      assert.ok(g.segments >= 3, `segments: ${g.segments}`);
      assert.ok(g.bounds.length >= 1);
      await screenshot(page, "editor-surface-texture.png");
      // A click on empty texture space clears the selection; a click on the outline selects it.
      const uvBox = await page.$eval("#uv", (c) => { const r = c.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
      await page.mouse.click(uvBox[0] + 4, uvBox[1] + 4);
      await until(async () => (await state(page)).selection.length === 0, "nothing selected");
      await page.mouse.click(...g.center);
      await until(async () => (await state(page)).selection.join() === placedId, "selected from the texture view");
      const before = (await doc()).placements.find((p) => p.id === placedId);
      // A drop point a few pixels away whose texel lies on the body (a generated layout has gaps
      // between its charts: a drop there leaves the placement where it is, and says so).
      const o = (await api("GET", `/scenes/${sceneId}/placements/${placedId}/outline`)).body;
      const pxPerUV = await page.evaluate((id) => window.dermisEditor.screenGeometry(id).pxPerUV, placedId);
      let step = null;
      for (const [dx, dy] of [[4, 0], [0, 4], [-4, 0], [0, -4], [3, 3], [-3, -3], [6, 0], [0, 6]]) {
        const u = o.anchor_uv[0] + dx / pxPerUV, v = o.anchor_uv[1] + dy / pxPerUV;
        const hit = (await api("GET", `/scenes/${sceneId}/pick?u=${u}&v=${v}`)).body;
        if (hit.hit && Math.hypot(...hit.anchor.position.map((x, i) => x - before.anchor.position[i])) > 1e-5) { step = [dx, dy]; break; }
      }
      assert.ok(step, "a texel on the body beside the anchor's");
      // The slide's answer comes back late (the server has applied it): an undo pressed as soon as
      // the server has the move undoes the move, not the add before it (which would take the
      // placement away — what CI once saw under ASan, where answers are slow).
      const patchPath = `/api/v1/scenes/${sceneId}/placements/${encodeURIComponent(placedId)}`;
      const late = (url) => url.pathname === patchPath;
      const lateAnswers = await holdAnswers(page, late, { methods: ["PATCH"], ms: 1500 });
      await page.mouse.move(...g.center);
      await page.mouse.down();
      await page.mouse.move(g.center[0] + step[0] / 2, g.center[1] + step[1] / 2);
      await page.mouse.move(g.center[0] + step[0], g.center[1] + step[1]);
      await page.mouse.up();
      const moved = await until(async () => { const p = (await doc()).placements.find((q) => q.id === placedId); return !near(p.anchor.position, before.anchor.position, 1e-6) && p; }, "the anchor moved");
      assert.equal(moved.projection, "surface");
      assert.deepEqual(moved.size, before.size);
      await page.keyboard.press("Control+z"); // while the move's answer is still on its way
      const back = await until(async () => { const d = await doc(); const p = d.placements.find((q) => q.id === placedId); return (!p || near(p.anchor.position, before.anchor.position, 1e-9)) && { p }; }, "undo puts it back");
      assert.ok(back.p, "the undo took the placement away: it undid the add, not the move");
      await lateAnswers.stop();
      // The same slide on a slow link (its pick and its edit answered 700 ms late): the outline
      // stays where it was let go of until its new outline is in; it never snaps back meanwhile.
      await until(async () => !(await page.evaluate(() => window.dermisEditor.store.busy)), "the undo answered");
      // Its own outline read again after the undo (the moved one shows until it is in).
      await until(async () => { const c = await page.evaluate((id) => window.dermisEditor.screenGeometry(id)?.center, placedId);
                                return c && Math.hypot(c[0] - g.center[0], c[1] - g.center[1]) < 1; }, "drawn back at its first place");
      const slow = await holdAnswers(page, (url) => url.pathname === patchPath || url.pathname.endsWith("/pick"), { ms: 700 });
      const drop = [g.center[0] + step[0], g.center[1] + step[1]];
      await page.mouse.move(...g.center);
      await page.mouse.down();
      await page.mouse.move(g.center[0] + step[0] / 2, g.center[1] + step[1] / 2);
      await page.mouse.move(...drop);
      await page.mouse.up();
      const samples = [];
      const t0 = Date.now();
      while (Date.now() - t0 < 3500) {
        const s = await page.evaluate((id) => { const s = window.dermisEditor.screenGeometry(id); return s && { c: s.center, b: s.bounds[0] }; }, placedId);
        samples.push(s && { ...s, early: Date.now() - t0 < 600 }); // the pick is held 700 ms: still the old outline
        await sleep(40);
      }
      await slow.stop();
      const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
      for (const s of samples) {
        assert.ok(s && dist(s.c, drop) < dist(s.c, g.center), `drawn near the drop (${drop}), not back at ${g.center}: ${s && s.c}`);
        // Its pieces' bounds (what a press hits) move with what is drawn: the pointer finds it there.
        if (s.early) assert.ok(dist([s.b[0] - g.bounds[0][0], s.b[1] - g.bounds[0][1]], [s.c[0] - g.center[0], s.c[1] - g.center[1]]) < 0.5,
                               `bounds ${s.b} moved as the centre ${s.c} (from ${g.bounds[0]}, ${g.center})`);
      }
      assert.ok(samples.some((s) => s.early), "sampled before the pick was answered");
      await until(async () => !near((await doc()).placements.find((q) => q.id === placedId).anchor.position, before.anchor.position, 1e-6), "and it moved on the server");
    }],
    ["+ scales its size in model units and ] turns it", async () => {
      const before = (await doc()).placements.find((p) => p.id === placedId);
      await page.focus("#uv");
      await page.keyboard.press("+");
      await page.keyboard.press("]");
      const after = await until(async () => { const p = (await doc()).placements.find((q) => q.id === placedId); return p.rotation !== before.rotation && p.size[0] !== before.size[0] && p; }, "size and rotation changed");
      assert.ok(Math.abs(after.size[0] / before.size[0] - 1.05) < 1e-3, `${after.size} vs ${before.size}`);
      assert.equal(after.rotation, before.rotation + 5);
      assert.equal(after.center === undefined || JSON.stringify(after.center) === JSON.stringify(before.center), true, "no UV centre invented");
    }],
    ["three quick arrows on the body move it three texels, each from where the one before left it (answers held 1 s)", async () => {
      const size = (await doc()).heightmap?.size?.[0] || 1024;
      const r0 = (await api("GET", `/scenes/${sceneId}`)).body.revision;
      const o0 = (await api("GET", `/scenes/${sceneId}/placements/${placedId}/outline`)).body;
      // An arrow whose next three texels all lie on the body (a generated layout's charts end somewhere).
      const arrows = { ArrowRight: [1, 0], ArrowLeft: [-1, 0], ArrowDown: [0, 1], ArrowUp: [0, -1] };
      let key = null;
      for (const [k, [du, dv]] of Object.entries(arrows)) {
        let on = true;
        for (let n = 1; n <= 3 && on; ++n) {
          const u = o0.anchor_uv[0] + (n * du) / size, v = o0.anchor_uv[1] + (n * dv) / size;
          on = (await api("GET", `/scenes/${sceneId}/pick?u=${u}&v=${v}`)).body.hit;
        }
        if (on) { key = k; break; }
      }
      assert.ok(key, "an arrow with three texels of body beside the anchor");
      const patchPath = `/api/v1/scenes/${sceneId}/placements/${encodeURIComponent(placedId)}`;
      const late = (url) => url.pathname === patchPath;
      const lateAnswers = await holdAnswers(page, late, { methods: ["PATCH"], ms: 1000 });
      await page.focus("#uv");
      for (let k = 0; k < 3; ++k) await page.keyboard.press(key);
      await until(async () => (await api("GET", `/scenes/${sceneId}`)).body.revision >= r0 + 3, "three moves on the server", 20000);
      await until(async () => !(await page.evaluate(() => window.dermisEditor.store.busy)), "every answer in");
      await lateAnswers.stop();
      const o1 = (await api("GET", `/scenes/${sceneId}/placements/${placedId}/outline`)).body;
      const [du, dv] = arrows[key];
      const texels = ((o1.anchor_uv[0] - o0.anchor_uv[0]) * du + (o1.anchor_uv[1] - o0.anchor_uv[1]) * dv) * size;
      assert.ok(texels > 2.5 && texels < 3.5, `${key} ×3 moved it ${texels.toFixed(2)} texels (not one: each nudge reads the anchor the one before left)`);
    }],
    ["in the 3D view a drag that starts on the selected decal moves it, and the camera stays", async () => {
      const before = (await doc()).placements.find((p) => p.id === placedId);
      const cam0 = (await state(page)).camera;
      const [x, y] = await client(px);
      await page.mouse.move(x - 2, y);
      await page.mouse.move(x, y);
      await until(async () => (await param("hover")) === placedId || (await param("highlight")) === placedId && (await page.evaluate(async () => (await import("/js/camera3d.js")).pointer.hover)) === placedId, "the decal under the pointer");
      await page.mouse.down();
      for (let k = 1; k <= 6; ++k) { await page.mouse.move(x + k * 3, y + k); await sleep(60); }
      await page.mouse.up();
      const moved = await until(async () => { const p = (await doc()).placements.find((q) => q.id === placedId); return !near(p.anchor.position, before.anchor.position, 1e-6) && p; }, "the anchor moved", 15000);
      assert.equal(moved.projection, "surface");
      const cam1 = (await state(page)).camera;
      assert.equal(cam1.yaw, cam0.yaw, "no orbit");
      assert.equal(cam1.pitch, cam0.pitch, "no orbit");
    }],
    ["Place as: in the texture adds a UV placement", async () => {
      const n0 = (await doc()).placements.length;
      await page.evaluate(() => { const s = document.getElementById("placeAs"); s.value = "uv"; s.dispatchEvent(new Event("change")); });
      await page.click("#placeTool");
      const [x, y] = await client([px[0], px[1] + 30]);
      await page.mouse.move(x, y);
      await until(async () => param("brush"), "a UV brush");
      await page.mouse.click(x, y);
      const d = await until(async () => { const s = await doc(); return s.placements.length === n0 + 1 && s; }, "a new placement");
      const p = d.placements[d.placements.length - 1];
      assert.notEqual(p.projection, "surface");
      assert.equal(p.center.length, 2);
      assert.deepEqual(page.errors, []);
    }],
    ["Propose… on the body: every surface placement's label is laid out with the others, none overlaps another", async () => {
      // Before, a surface placement's label was written at its anchor, outside the label layout:
      // Propose…'s fifteen on the Barbarian printed "left elbow crease" over "left elbow tip".
      await page.keyboard.press("Escape");
      await page.click("#propose");
      await page.waitForSelector("#proposeAll:not([disabled])", { timeout: 60000 });
      const n0 = (await doc()).placements.length;
      await page.click("#proposeAll");
      const d = await until(async () => { const s = await doc(); return s.placements.length > n0 + 5 && s; }, "the proposals added");
      await page.keyboard.press("Escape");
      const surface = d.placements.filter((q) => q.projection === "surface").map((q) => q.id);
      assert.ok(surface.length > 5, `surface placements (${surface.length})`);
      await page.evaluate(() => window.dermisEditor.select([]));
      const l = await until(async () => {
        const l = await page.evaluate(() => window.dermisEditor.labelLayout());
        const laid = new Set([...l.shown.map((b) => b.id), ...l.hidden]);
        return surface.every((id) => laid.has(id)) && l;
      }, "every surface placement in the label layout (its outline in)", 30000);
      const overlaps = [];
      for (let i = 0; i < l.shown.length; ++i)
        for (let j = i + 1; j < l.shown.length; ++j) {
          const a = l.shown[i], b = l.shown[j];
          if (a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h) overlaps.push(`${a.id}/${b.id}`);
        }
      assert.deepEqual(overlaps, [], "no two labels overlap");
      assert.ok(l.shown.filter((b) => surface.includes(b.id)).length >= surface.length / 2, `most surface labels shown (${l.shown.length} shown, ${l.hidden.length} hidden)`);
      // The list: each surface row is tagged ◍ (its words in the accessible name), and the tag
      // leaves the name its room: "left elbow crease" is whole at 1600 px.
      const rows = await page.$$eval("#placementList li", (ls) => ls.map((li) => ({ id: li.dataset.placement, tag: li.querySelector(".surfacetag")?.getAttribute("aria-label") || null,
        name: li.querySelector(".name").textContent, cut: li.querySelector(".name").scrollWidth > li.querySelector(".name").clientWidth + 1 })));
      for (const r of rows) assert.equal(r.tag, surface.includes(r.id) ? "on the body" : null, `the tag of ${r.id}`);
      const elbow = rows.find((r) => r.name === "left elbow crease");
      assert.ok(elbow && !elbow.cut, `"left elbow crease" whole in the list (${JSON.stringify(elbow)})`);
      await screenshot(page, "editor-surface-labels.png");
      assert.deepEqual(page.errors, []);
    }],
  ]);
  await context.close();
  return failures;
}, async () => { await browser.close(); server.stop(); });
