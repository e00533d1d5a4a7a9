// WebEditorProposeBrowserTest — a new character's whole pattern set in a few clicks (issue #23
// item 5, SPEC §8), in Debian's Chromium (playwright-core) against a real dermis-server on
// 127.0.0.1: New from model… (CesiumMan, a character the editor has never seen), Propose…, Accept
// all, Sweep the clip. Every UI action (click, key press, file choice) is counted and the wall
// time from the upload to the sweep on screen measured; both are printed as one JSON line
// ({"ui_actions": N, "seconds": S}) and the count must be ≤ 10.
// Usage: node editor_propose.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the list shows every proposal with kind, driver, θ range, score and why, all ticked;
// Accept all adds them all in ONE revision (op "propose"), among them a crease at each elbow and
// knee driven by that joint; the sheet differs from the same sheet without patterns, and so do
// frames at the knee's peak; a row's preview is that proposal alone (its pixels found) and the 3D
// view circles its anchor (surface_brush); rows the scene has say "in the scene" and cannot be
// ticked; one Ctrl+Z takes the whole set back; Accept selected adds a subset in one revision;
// Transfer from… (the default character's scene, plus a knuckle CesiumMan has no finger for)
// previews the joint map, lists what comes over and what does not (and why), and applies it in one
// revision; new placements of the place tool are labelled by their joint's role when pick names it;
// A opens the panel from the keyboard (↑ ↓ Space Esc in its list), which fits at 1280×720; "Go to
// θmax" poses a proposal's vector axis exactly (a rotation override).
// Screenshots: editor-propose-list.png, editor-propose-sweep.png, editor-propose-accepted.png,
// editor-transfer.png.
import assert from "node:assert/strict";
import { existsSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { startServer, launch, apiClient, openEditor, state, screenshot, runChecks, runSuite, until, settled, settledFrameHash, selectPlacement } from "./editor_lib.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const testModels = process.env.DERMIS_TEST_MODELS || join(here, "../models");
const cesium = join(testModels, "CesiumMan/CesiumMan.glb");
assert.ok(existsSync(cesium), `CesiumMan at ${cesium}`);

const server = await startServer(process.argv[2], [], "dermis-editor-propose-");
const api = apiClient(server.base);
const browser = await launch();

await runSuite("WebEditorProposeBrowserTest", async () => {
  const context = await browser.newContext();
  const page = await openEditor(context, `${server.base}/`, { width: 1600, height: 1000 });
  const defaultScene = (await state(page)).sceneId;
  // Every UI action of the timed workflow goes through these.
  let actions = 0;
  const click = async (selector) => { ++actions; await page.click(selector); };
  const press = async (key) => { ++actions; await page.keyboard.press(key); };
  const param = async (name) => new URL("http://x/api/v1" + await page.evaluate(() => window.dermisEditor.frameUrl())).searchParams.get(name);
  const scene = async (id) => (await api("GET", `/scenes/${id}`)).body;
  let sceneId = null, proposals = null, revisionBefore = 0, sweepSrc = null;

  const failures = await runChecks("WebEditorProposeBrowserTest", [
    ["upload → Propose… → Accept all → sweep of the clip: ≤ 10 UI actions", async () => {
      const t0 = Date.now();
      const [chooser] = await Promise.all([page.waitForEvent("filechooser"), click("#newScene")]);
      ++actions; // the file choice
      await chooser.setFiles(cesium);
      await page.waitForFunction((first) => { const s = window.dermisEditor.store; return s.sceneId !== first && s.model && s.model.name === "CesiumMan"; }, defaultScene, { timeout: 60000 });
      sceneId = (await state(page)).sceneId;
      revisionBefore = (await scene(sceneId)).revision;
      await click("#propose");
      await page.waitForSelector("#proposalList li", { timeout: 30000 });
      await click("#proposeAll");
      await until(async () => (await state(page)).revision > revisionBefore && (await page.$("#proposeSweep:not([hidden])")), "the set added and the sweep offered", 30000);
      await click("#proposeSweep");
      await page.waitForFunction(() => { const i = document.getElementById("sweepSheet"); return i && i.complete && i.naturalWidth > 0 && document.getElementById("sweepDialog").open; }, null, { timeout: 60000 });
      const seconds = (Date.now() - t0) / 1000;
      sweepSrc = await page.$eval("#sweepSheet", (i) => i.getAttribute("src"));
      console.log(JSON.stringify({ ui_actions: actions, seconds: Math.round(seconds * 10) / 10 }));
      await screenshot(page, "editor-propose-sweep.png");
      assert.ok(actions <= 10, `${actions} UI actions`);
      await press("Escape"); // closes the sweep (not counted in the timed part above)
    }],
    ["Accept all added every proposal in ONE revision (op propose): a crease at each elbow and knee", async () => {
      const s = await scene(sceneId);
      assert.equal(s.revision, revisionBefore + 1, "one revision");
      const revs = (await api("GET", `/scenes/${sceneId}/revisions?limit=5`)).body.revisions;
      assert.equal(revs.find((r) => r.revision === s.revision).op, "propose");
      const answer = (await api("POST", `/scenes/${sceneId}/propose`, {})).body;
      proposals = answer.proposals;
      assert.ok(proposals.length >= 4, `${proposals.length} proposals`);
      assert.ok(proposals.every((p) => p.existing), "every proposal is in the scene now");
      const ids = new Set(s.scene.placements.map((p) => p.id));
      for (const p of proposals) assert.ok(ids.has(p.existing), `${p.existing} in the scene`);
      for (const role of ["left elbow", "right elbow", "left knee", "right knee"]) {
        const crease = proposals.find((p) => p.kind === "crease" && p.why.role === role);
        assert.ok(crease, `a crease at the ${role}`);
        const placed = s.scene.placements.find((q) => q.id === crease.existing);
        assert.equal(placed.joint, crease.why.joint, `the ${role} crease is driven by that joint`);
        assert.equal(placed.projection, "surface");
      }
      // The list showed them all, each with its words.
      const rows = await page.$$eval("#proposalList li", (l) => l.map((li) => ({ id: li.dataset.id, text: li.textContent, existing: li.classList.contains("existing"), box: li.querySelector("input.accept").disabled })));
      assert.equal(rows.length, proposals.length);
      assert.ok(rows.every((r) => r.existing && r.box), "rows in the scene say so and cannot be ticked");
      assert.ok(rows.every((r) => /in the scene/.test(r.text)));
      const knee = rows.find((r) => /left knee crease/.test(r.text));
      assert.match(knee.text, /left knee bends 0–\d+(\.\d)?° \(\w+ at [\d.]+ s\) · compresses \d+ %/);
      assert.match(knee.text, /θ 0–\d/);
    }],
    ["the patterns show: the sweep and the frames differ from the same without patterns", async () => {
      const withP = await api("GET", sweepSrc.replace(/^\/api\/v1/, ""));
      const without = await api("GET", sweepSrc.replace(/^\/api\/v1/, "") + "&patterns=off");
      assert.equal(withP.status, 200);
      assert.equal(without.status, 200);
      assert.ok(!withP.body.equals(without.body), "the sheet changes with the patterns");
      for (const role of ["left knee", "right knee"]) {
        const crease = proposals.find((p) => p.kind === "crease" && p.why.role === role);
        let changed = 0;
        for (const yaw of [0, 180]) {
          const d = await api("GET", `/scenes/${sceneId}/frame-diff?against=off&time=${crease.why.peak_time}&yaw=${yaw}&width=512&height=512`);
          changed = Math.max(changed, +d.headers.get("x-dermis-changed-pixels"));
        }
        assert.ok(changed > 0, `${role}: the frame at its peak changes with the patterns`);
      }
    }],
    ["one Ctrl+Z takes the whole set back; the rows are new again and ticked", async () => {
      await page.focus("#frameStage");
      await page.keyboard.press("Control+z");
      await until(async () => (await scene(sceneId)).scene.placements.length === 0, "undone");
      await page.waitForFunction(() => { const l = [...document.querySelectorAll("#proposalList li")]; return l.length && l.every((li) => !li.classList.contains("existing") && li.querySelector("input.accept").checked); }, null, { timeout: 15000 });
    }],
    ["a row's preview is that proposal alone, and the 3D view circles its anchor", async () => {
      const knee = proposals.find((p) => p.kind === "crease" && p.why.role === "left knee");
      const id = knee.placement.id;
      await page.click(`#proposalList li[data-id="${id}"] .name`);
      await page.waitForFunction((pid) => document.getElementById("proposePreview").dataset.proposal === pid, id, { timeout: 30000 });
      const pixels = await page.$eval("#proposePreview", (c) => +c.dataset.pixels);
      assert.ok(pixels > 0, "the pattern's pixels were found in the height view");
      const a = knee.placement.anchor;
      const want = [...a.position, ...a.normal, Math.max(...knee.placement.size)].map((x) => Math.round(x * 1e5) / 1e5);
      await until(async () => { const b = await param("surface_brush"); return b && b.split(",").map(Number).every((x, i) => Math.abs(x - want[i]) < 1e-5); }, "the ghost at the knee crease's anchor");
      // The texture view draws every proposal not in the scene as a dashed violet outline (the
      // propose answer's outline in the layout in use).
      assert.ok(proposals.every((p) => p.outline && p.outline.segments.length > 0), "each proposal has an outline");
      const violet = () => page.$eval("#uv", (c) => {
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 180) < 24 && Math.abs(d[i + 1] - 140) < 24 && d[i + 2] > 220) ++n;
        return n;
      });
      await until(async () => (await violet()) > 50, "the texture view shows the proposals' outlines");
      await page.keyboard.press("ArrowDown");
      const next = proposals[proposals.findIndex((p) => p.placement.id === id) + 1];
      if (next) await page.waitForFunction((pid) => document.querySelector("#proposalList li.selected")?.dataset.id === pid, next.placement.id, { timeout: 15000 });
      await page.keyboard.press("ArrowUp");
      await page.waitForFunction((pid) => document.getElementById("proposePreview").dataset.proposal === pid, id, { timeout: 30000 });
      // The knee crease shows from behind: "Turn 3D there" turns the view to its circle.
      const yaw0 = (await state(page)).camera.yaw;
      await page.click("#proposeLook");
      await until(async () => Math.abs(((await state(page)).camera.yaw - yaw0 + 360) % 360 - 180) < 1e-6, "the 3D view turned round");
      await settledFrameHash(page);
      await screenshot(page, "editor-propose-list.png");
    }],
    ["Accept selected adds the ticked ones in ONE revision", async () => {
      const untick = proposals.filter((p) => p.kind === "bone").map((p) => p.placement.id);
      assert.ok(untick.length >= 1);
      for (const id of untick) await page.click(`#proposalList li[data-id="${id}"] input.accept`);
      const r0 = (await scene(sceneId)).revision;
      await page.click("#proposeSelected");
      const s = await until(async () => { const d = await scene(sceneId); return d.revision > r0 && d; }, "a revision");
      await settled(page, api);
      const after = await scene(sceneId);
      assert.equal(after.revision, r0 + 1, "one revision");
      assert.equal(s.scene.placements.length, proposals.length - untick.length);
      for (const id of untick) assert.ok(!s.scene.placements.some((p) => p.id === id), `${id} left out`);
      await page.waitForFunction((n) => document.querySelectorAll("#proposalList li.existing").length === n, proposals.length - untick.length, { timeout: 15000 });
      // The clip at the right knee's peak, from behind (where the creases face): the patterns at work.
      const knee = proposals.find((p) => p.kind === "crease" && p.why.role === "right knee");
      await page.selectOption("#clip", knee.why.peak_clip);
      await page.evaluate(async (t) => (await import("/js/store.js")).set({ time: t, camera: { ...window.dermisEditor.store.camera, yaw: 180 } }), knee.why.peak_time);
      await settled(page, api);
      await page.waitForFunction((n) => new RegExp(`· ${n} placements`).test(document.getElementById("scene").selectedOptions[0]?.textContent || ""), proposals.length - untick.length, { timeout: 10000 });
      await settledFrameHash(page);
      await screenshot(page, "editor-propose-accepted.png");
      await page.focus("#proposalList");
      await page.keyboard.press("Escape");
      await page.waitForFunction(() => document.getElementById("proposePanel").hidden, null, { timeout: 15000 });
      assert.equal(await param("surface_brush"), null, "no ghost once the panel is closed");
      await until(async () => (await page.$eval("#uv", (c) => {
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 180) < 24 && Math.abs(d[i + 1] - 140) < 24 && d[i + 2] > 220) ++n;
        return n;
      })) === 0, "no texture ghosts once the panel is closed");
    }],
    ["keyboard: A opens Propose… with the focus in the list; ↓ and Space walk and untick; Esc closes; at 1280×720 it fits", async () => {
      await page.setViewportSize({ width: 1280, height: 720 });
      await page.focus("#frameStage");
      await page.keyboard.press("a");
      await page.waitForFunction(() => document.activeElement && document.activeElement.id === "proposalList" && document.querySelectorAll("#proposalList li").length > 0, null, { timeout: 15000 });
      const first = await page.$eval("#proposalList li.selected", (li) => li.dataset.id);
      await page.keyboard.press("ArrowDown");
      const second = await page.$eval("#proposalList li.selected", (li) => li.dataset.id);
      assert.notEqual(first, second);
      const fresh = await page.$eval("#proposalList li.selected", (li) => !li.classList.contains("existing"));
      if (fresh) {
        const before = await page.$eval("#proposalList li.selected input.accept", (c) => c.checked);
        await page.keyboard.press(" ");
        assert.equal(await page.$eval("#proposalList li.selected input.accept", (c) => c.checked), !before, "Space ticks / unticks");
        await page.keyboard.press(" ");
      }
      for (const sel of ["#proposeAll", "#proposeSelected", "#proposePreview", "#proposalList"]) {
        const b = await page.$eval(sel, (e) => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; });
        assert.ok(b[0] >= 0 && b[1] >= 0 && b[2] <= 1280 && b[3] <= 720 && b[3] > b[1], `${sel} in view at 1280×720: ${b}`);
      }
      await page.keyboard.press("Escape");
      await page.waitForFunction(() => document.getElementById("proposePanel").hidden, null, { timeout: 15000 });
      await page.setViewportSize({ width: 1600, height: 1000 });
    }],
    ["Go to θmax on a proposal's vector axis poses its joint there", async () => {
      const knee = proposals.find((p) => p.kind === "crease" && p.why.role === "left knee");
      const id = knee.placement.id;
      assert.ok(Array.isArray(knee.placement.axis), "proposals drive by a vector axis");
      await selectPlacement(page, id);
      await page.waitForSelector("#goMax");
      assert.equal(await page.$eval("#pAxis", (e) => e.value), "vector", "the axis field shows the vector");
      await page.click("#goMax");
      await until(async () => (await scene(sceneId)).scene.pose.joints?.[knee.placement.joint]?.rotation, "a rotation override of the knee");
      const time = (await scene(sceneId)).scene.pose.time ?? 0;
      const drivers = (await api("GET", `/scenes/${sceneId}/drivers?time=${time}`)).body.placements;
      const d = drivers.find((q) => q.placement === id);
      assert.ok(Math.abs(d.theta - knee.placement.theta_max) < 0.05, `θ ${d.theta} vs θmax ${knee.placement.theta_max}`);
      assert.ok(d.t > 0.99, `t ${d.t}`);
      const slider = await until(async () => {
        const v = await page.$eval(`#jointSliders input[data-joint="${knee.placement.joint}"]`, (e) => ({ value: +e.value, label: e.closest("label").textContent }));
        return Math.abs(v.value - knee.placement.theta_max) <= 0.5 && v;
      }, "the knee's slider at θmax");
      assert.doesNotMatch(slider.label, /\d\.\d{4}/, "the slider names the axis briefly");
      await page.click("#clearPose");
    }],
    ["Transfer from… the default character's set: the preview lists what comes over and what does not", async () => {
      // The source: the default character's scene with its pattern set, plus a knuckle on a finger
      // joint CesiumMan does not have.
      const src = (await scene(defaultScene)).scene;
      const base = src.placements[0];
      const knuckle = { ...base, id: "knuckle_l", label: "left index knuckle", joint: "index_02.l" };
      const added = await api("POST", `/scenes/${defaultScene}/placements`, knuckle);
      assert.equal(added.status, 201, JSON.stringify(added.body));
      const target = await api("POST", "/scenes", { format: "dermis.scene/1", model: (await scene(sceneId)).scene.model, placements: [] });
      assert.equal(target.status, 201);
      await page.goto(`${server.base}/?scene=${target.body.id}`);
      await page.waitForFunction((id) => window.dermisEditor && window.dermisEditor.store.sceneId === id && window.dermisEditor.store.doc, target.body.id, { timeout: 30000 });
      await page.click("#transferFrom");
      await page.selectOption("#transferSource", defaultScene);
      await page.waitForSelector("#transferList li", { state: "attached", timeout: 30000 });
      const preview = (await api("POST", `/scenes/${target.body.id}/transfer?apply=false`, { from: defaultScene })).body;
      assert.ok(preview.transferred.length > 0);
      assert.equal(await page.$$eval("#transferList li", (l) => l.length), preview.transferred.length);
      const lost = await page.$$eval("#transferUnmapped li", (l) => l.map((e) => e.textContent));
      assert.equal(lost.length, preview.unmapped.length);
      assert.ok(lost.some((t) => /knuckle/.test(t) && /index_02\.l/.test(t)), `the knuckle is listed with its reason: ${lost}`);
      assert.match(await page.$eval("#transferGo", (b) => b.textContent), new RegExp(`Transfer ${preview.transferred.length}`));
      await screenshot(page, "editor-transfer.png");
      const r0 = (await scene(target.body.id)).revision;
      await page.click("#transferGo");
      await page.waitForFunction(() => /Transferred \d+ in one revision/.test(document.getElementById("transferResult").textContent), null, { timeout: 30000 });
      const after = await scene(target.body.id);
      assert.equal(after.revision, r0 + 1, "one revision");
      assert.equal(after.scene.placements.length, preview.transferred.length);
      await page.keyboard.press("Escape");
    }],
    ["the place tool labels a new placement by its joint's role (when pick names it)", async () => {
      const found = await page.evaluate(async () => {
        for (const y of [0.3, 0.35, 0.4, 0.45]) for (const x of [0.5, 0.45, 0.55]) {
          const n = 512, hit = await window.dermisEditor.pickAt(Math.floor(n * x), Math.floor(n * y));
          if (hit.hit && hit.anchor && hit.suggested) return { px: [Math.floor(n * x), Math.floor(n * y)], hit };
        }
        return null;
      });
      assert.ok(found, "a pixel on the body");
      const pattern = await page.evaluate(async () => (await import("/js/panels/library.js")).currentPattern());
      const name = (pattern.name || pattern.id).replace(/_/g, " ");
      const box = await page.$eval("#frame", (i) => { const r = i.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
      const side = Math.min(box[2], box[3]);
      const x = box[0] + (box[2] - side) / 2 + (found.px[0] + 0.5) / 512 * side, y = box[1] + (box[3] - side) / 2 + (found.px[1] + 0.5) / 512 * side;
      const id = (await state(page)).sceneId, n0 = (await scene(id)).scene.placements.length;
      await page.focus("#frameStage");
      await page.keyboard.press("p");
      await page.mouse.move(x - 2, y);
      await page.mouse.move(x, y);
      await page.mouse.click(x, y);
      const d = await until(async () => { const s = (await scene(id)).scene; return s.placements.length === n0 + 1 && s; }, "a new placement");
      const placed = d.placements[d.placements.length - 1];
      await page.keyboard.press("p");
      const role = found.hit.suggested.role;
      console.log(`    pick suggests ${JSON.stringify(found.hit.suggested)}; placed "${placed.label}" ${placed.size} wide`);
      if (role) assert.equal(placed.label, `${role} ${name}`);
      else assert.equal(placed.label, "", "no role from pick yet: no label");
      // The label rule itself, whatever pick says today.
      const withRole = await page.evaluate(async (pat) => (await import("/js/placing.js")).applySuggested({}, { joint: "j", axis: "x", theta_min: 0, theta_max: 90, role: "left elbow" }, pat), pattern);
      assert.equal(withRole.label, `left elbow ${name}`);
    }],
    ["no script errors", async () => { assert.deepEqual(page.errors, []); }],
  ]);
  await context.close();
  return failures;
}, async () => { await browser.close(); server.stop(); });
