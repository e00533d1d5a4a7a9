// WebEditorPanelsBrowserTest — the editor's panels and 3D view in Debian's Chromium
// (playwright-core) against a real dermis-server on 127.0.0.1, and the drag-to-frame benchmark.
// Usage: node editor_panels.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: dropping a PNG uploads it, dropping a text file shows an error and posts nothing;
// parameter edits change the server document and the response plot; a joint slider and the clip
// scrubber change the frame; view modes; compare split / flicker / diff; the place tool adds a
// placement at the clicked skin with the suggested driver; a click on the model selects the
// placement there, and a click whose pick answers late does not undo a later choice in the list;
// Alt+↓ reorders; the activation strip jumps in time;
// the sweep dialog; a server error appears on screen. Then 100 pointer moves of a drag are timed
// to the frame on screen (p50/p95, JSON on stdout and in $DERMIS_TEST_OUT/editor-drag-bench.json).
import assert from "node:assert/strict";
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { startServer, launch, apiClient, openEditor, settledFrameHash, state, footprint, screenshot, runChecks, runSuite, settled, until, sleep, shotDir, selectPlacement, holdAnswers } from "./editor_lib.mjs";

const server = await startServer(process.argv[2], [], "dermis-editor-panels-");
const api = apiClient(server.base);
const browser = await launch();
await runSuite("WebEditorPanelsBrowserTest", async () => {
  const context = await browser.newContext();
  const page = await openEditor(context, server.base + "/");
  const sceneId = (await state(page)).sceneId;
  const doc = async () => (await api("GET", `/scenes/${sceneId}`)).body.scene;
  const select = (id) => selectPlacement(page, id);
  const settle = () => settled(page, api);
  const uploads = [];
  page.on("request", (r) => { if (r.method() === "POST" && new URL(r.url()).pathname === "/api/v1/patterns") uploads.push(r.url()); });
  /// Drops a file (name, MIME type, bytes from `fromUrl` or the text `text`) on `selector`.
  const dropFile = (selector, name, type, { fromUrl, text }) => page.evaluate(async ([sel, n, t, u, txt]) => {
    const bytes = u ? await (await fetch(u)).arrayBuffer() : new TextEncoder().encode(txt);
    const dt = new DataTransfer();
    dt.items.add(new File([bytes], n, { type: t }));
    const target = document.querySelector(sel);
    target.dispatchEvent(new DragEvent("dragover", { dataTransfer: dt, bubbles: true, cancelable: true }));
    target.dispatchEvent(new DragEvent("drop", { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, [selector, name, type, fromUrl, text]);
  const noticeMatching = (re) => page.waitForFunction((src) => [...document.querySelectorAll("#notices .notice")].some((n) => new RegExp(src).test(n.textContent)), re.source, { timeout: 10000 });

  let failures = await runChecks("WebEditorPanelsBrowserTest", [
    ["dropping a PNG on the library uploads it", async () => {
      const n0 = (await api("GET", "/patterns")).body.patterns.length;
      await dropFile("#patternDrop", "my_wrinkle.png", "image/png", { fromUrl: "/api/v1/patterns/crease/image?size=128" });
      const list = await until(async () => { const l = (await api("GET", "/patterns")).body.patterns; return l.length === n0 + 1 && l; }, "one more pattern on the server");
      const added = list.find((p) => !p.builtin);
      assert.ok(added && /my_wrinkle/.test(added.name), JSON.stringify(added));
      await page.waitForSelector(`#libraryList button[data-pattern="${added.id}"]`, { timeout: 15000 });
      assert.equal(uploads.length, 1);
    }],
    ["dropping a text file shows an error and posts nothing", async () => {
      uploads.length = 0;
      await dropFile("#patternDrop", "notes.txt", "text/plain", { text: "not an image" });
      await noticeMatching(/not an image/);
      await sleep(300);
      assert.equal(uploads.length, 0);
    }],
    ["parameter edits change the response plot and the server document", async () => {
      await select("elbow_l");
      const curve0 = await page.$eval("#plot", (c) => c.dataset.curve);
      await page.fill("#pH", "0.5");
      await page.press("#pH", "Enter");
      await until(async () => (await doc()).placements.find((p) => p.id === "elbow_l").h === 0.5, "h = 0.5 on the server");
      await until(async () => (await page.$eval("#plot", (c) => c.dataset.curve)) !== curve0, "the plot changed");
      const curve1 = await page.$eval("#plot", (c) => c.dataset.curve);
      await page.selectOption("#pResponse", "linear");
      await until(async () => (await doc()).placements.find((p) => p.id === "elbow_l").response === "linear", "linear response on the server");
      await until(async () => (await page.$eval("#plot", (c) => c.dataset.curve)) !== curve1, "the plot changed again");
      assert.equal(await page.$eval("#plot", (c) => c.dataset.curve), "0.0000,0.1250,0.2500,0.3750,0.5000");
      await page.fill("#pMax", "100");
      await page.press("#pMax", "Enter");
      await until(async () => (await doc()).placements.find((p) => p.id === "elbow_l").theta_max === 100, "θmax on the server");
      await screenshot(page, "editor-parameters.png");
    }],
    ["a joint slider changes the pose and the frame", async () => {
      await settle();
      const hash0 = await settledFrameHash(page);
      const slider = await page.$('#jointSliders input[data-joint="forearm.l"]');
      assert.ok(slider, "a slider for forearm.l (it drives elbow_l)");
      await slider.evaluate((el) => { el.value = "60"; el.dispatchEvent(new Event("input", { bubbles: true })); el.dispatchEvent(new Event("change", { bubbles: true })); });
      await until(async () => { const j = (await doc()).pose.joints["forearm.l"]; return j && j.axis_angles && j.axis_angles.x === 60; }, "the pose override on the server");
      await settle();
      assert.notEqual(await settledFrameHash(page), hash0);
    }],
    ["the clip scrubber changes the frame", async () => {
      const hash0 = await settledFrameHash(page);
      await page.$eval("#time", (el) => { el.value = "0.4"; el.dispatchEvent(new Event("input", { bubbles: true })); });
      assert.equal((await state(page)).time, 0.4);
      await until(() => page.$eval("#frame", (i) => /time=0\.4(&|$)/.test(i.dataset.url || "")), "a frame at t = 0.4");
      assert.notEqual(await settledFrameHash(page), hash0);
    }],
    ["compare: split, flicker and the diff heat map", async () => {
      await page.selectOption("#compareMode", "split");
      await page.waitForFunction(() => { const c = document.getElementById("compareFrame"); return !c.hidden && c.complete && c.naturalWidth > 0 && /patterns=off/.test(c.dataset.url || ""); }, null, { timeout: 20000 });
      assert.match(await page.$eval("#compareFrame", (c) => c.style.clipPath), /inset/);
      await page.$eval("#split", (el) => { el.value = "0.25"; el.dispatchEvent(new Event("input", { bubbles: true })); });
      assert.match(await page.$eval("#compareFrame", (c) => c.style.clipPath), /25%/);
      await screenshot(page, "editor-compare-split.png");
      await page.selectOption("#compareMode", "flicker");
      const seen = new Set();
      for (let i = 0; i < 12; ++i) { seen.add(await page.$eval("#compareFrame", (c) => c.style.visibility)); await sleep(100); }
      assert.ok(seen.has("hidden") && seen.has("visible"), [...seen].join(","));
      await page.selectOption("#compareMode", "diff");
      await until(() => page.$eval("#frame", (i) => /frame-diff/.test(i.dataset.url || "") && i.complete), "the diff heat map");
      await until(() => page.$eval("#diffText", (e) => /^\d+ px changed$/.test(e.textContent)), "changed pixels shown");
      await page.selectOption("#compareMode", "off");
    }],
    ["view modes: bump view", async () => {
      const hash0 = await settledFrameHash(page);
      await page.selectOption("#viewMode", "bump");
      await until(() => page.$eval("#frame", (i) => /view=bump/.test(i.dataset.url || "")), "a bump-view frame");
      assert.notEqual(await settledFrameHash(page), hash0);
      await page.selectOption("#viewMode", "shaded");
    }],
    ["view modes: skin shading for this view, the scene untouched", async () => {
      const hash0 = await settledFrameHash(page);
      const rev0 = (await state(page)).revision;
      await page.selectOption("#viewMode", "skin");
      await until(() => page.$eval("#frame", (i) => /shading=skin/.test(i.dataset.url || "") && !/view=/.test(i.dataset.url || "")), "a skin-shaded frame");
      const skinHash = await settledFrameHash(page);
      assert.notEqual(skinHash, hash0, "skin shading draws another picture");
      await page.selectOption("#viewMode", "pbr");
      await until(() => page.$eval("#frame", (i) => /shading=pbr/.test(i.dataset.url || "")), "a pbr frame");
      const pbrHash = await settledFrameHash(page);
      assert.notEqual(pbrHash, skinHash, "pbr is not skin");
      assert.equal(pbrHash, hash0, "pbr is the default shading: the scene's own frame");
      await page.selectOption("#viewMode", "legacy");
      await until(() => page.$eval("#frame", (i) => /shading=legacy/.test(i.dataset.url || "")), "a legacy frame");
      assert.notEqual(await settledFrameHash(page), pbrHash, "legacy, the old look, is another picture");
      await screenshot(page, "editor-pbr-view.png");
      await page.selectOption("#viewMode", "skin-key");
      await until(() => page.$eval("#frame", (i) => /shading=skin/.test(i.dataset.url || "") && /key_light=on/.test(i.dataset.url || "")),
                  "a skin frame with the key light");
      assert.notEqual(await settledFrameHash(page), skinHash, "the key light and its shadows change the picture");
      await screenshot(page, "editor-skin-key-light.png");
      await page.selectOption("#viewMode", "shaded");
      await until(() => page.$eval("#frame", (i) => !/shading=|key_light=/.test(i.dataset.url || "")), "the scene's own shading again");
      assert.equal((await state(page)).revision, rev0, "a view mode is no edit");
    }],
    ["the place tool adds a placement at the clicked skin with the suggested driver (Place as: in the texture)", async () => {
      await settle();
      const n0 = (await doc()).placements.length;
      await page.evaluate(() => { const s = document.getElementById("placeAs"); s.value = "uv"; s.dispatchEvent(new Event("change")); });
      await page.click("#placeTool");
      const box = await page.$eval("#frame", (i) => { const r = i.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
      const side = Math.min(box[2], box[3]);
      const at = [box[0] + (box[2] - side) / 2 + side * 0.5, box[1] + (box[3] - side) / 2 + side * 0.42]; // the torso
      await page.mouse.click(at[0], at[1]);
      // (A pick and an add on a sanitizer build of a busy machine took over 10 s once.)
      const d = await until(async () => { const x = await doc(); return x.placements.length === n0 + 1 && x; }, "a new placement", 30000);
      const added = d.placements[d.placements.length - 1];
      const pick = await page.evaluate(([x, y]) => window.dermisEditor.pickAt(x, y), [Math.floor(512 * 0.5), Math.floor(512 * 0.42)]);
      assert.ok(pick.hit);
      assert.equal(added.joint, pick.suggested.joint);
      assert.ok(Math.abs(added.center[0] - pick.uv[0]) < 0.002 && Math.abs(added.center[1] - pick.uv[1]) < 0.002);
      await page.click("#placeTool");
      await page.evaluate(() => { const s = document.getElementById("placeAs"); s.value = "surface"; s.dispatchEvent(new Event("change")); });
    }],
    ["clicking the model selects the placement there; the wheel zooms", async () => {
      await page.keyboard.press("Escape");
      // Find a frame pixel whose skin lies in a footprint (the editor's own pick), then click it.
      const target = await page.evaluate(async () => {
        const ed = window.dermisEditor, doc = ed.store.doc;
        const inside = (p, uv) => {
          const a = (p.rotation * Math.PI) / 180, c = Math.cos(a), s = Math.sin(a);
          const dx = uv[0] - p.center[0], dy = uv[1] - p.center[1];
          const x = (c * dx + s * dy) / p.scale[0] + 0.5, y = (-s * dx + c * dy) / p.scale[1] + 0.5;
          return x >= 0.1 && x <= 0.9 && y >= 0.1 && y <= 0.9;
        };
        for (let y = 140; y < 400; y += 12)
          for (let x = 200; x < 320; x += 12) {
            const hit = await ed.pickAt(x, y);
            if (!hit.hit) continue;
            const p = doc.placements.find((q) => inside(q, hit.uv));
            if (p && doc.placements.filter((q) => inside(q, hit.uv)).length === 1) return { x, y, id: p.id };
          }
        return null;
      });
      assert.ok(target, "a pixel on a footprint");
      const box = await page.$eval("#frame", (i) => { const r = i.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
      const side = Math.min(box[2], box[3]);
      await page.mouse.click(box[0] + (box[2] - side) / 2 + ((target.x + 0.5) / 512) * side, box[1] + (box[3] - side) / 2 + ((target.y + 0.5) / 512) * side);
      await until(async () => (await state(page)).selection[0] === target.id, `${target.id} selected by a click in 3D`);
      // A click whose pick answers late (1 s) after another placement was chosen in the list: the
      // list's choice stands (the late pick does not take the selection back).
      const late = (url) => url.pathname.endsWith("/pick") && url.searchParams.has("x");
      const lateAnswers = await holdAnswers(page, late);
      await page.keyboard.press("Escape");
      await page.mouse.click(box[0] + (box[2] - side) / 2 + ((target.x + 0.5) / 512) * side, box[1] + (box[3] - side) / 2 + ((target.y + 0.5) / 512) * side);
      const other = (await doc()).placements.find((p) => p.id !== target.id).id;
      await page.click(`#placementList li[data-placement="${other}"] .name`);
      await sleep(1500);
      await lateAnswers.stop();
      assert.deepEqual((await state(page)).selection, [other], "the list's later choice stands");
      await page.mouse.move(box[0] + box[2] / 2, box[1] + box[3] / 2); // back over the 3D view for the wheel
      const d0 = (await state(page)).camera.distance;
      await page.mouse.wheel(0, 300);
      await until(async () => { const d = (await state(page)).camera.distance; return d !== null && d !== d0; }, "the wheel set a distance");
      if (await page.isVisible("#viewMore")) await page.click("#viewMore"); // a narrow bar folds Reset into ⋯
      await page.click("#resetCamera");
    }],
    ["Alt+↓ on a placement row moves it down (server order)", async () => {
      const ids0 = (await doc()).placements.map((p) => p.id);
      await page.focus(`#placementList li[data-placement="${ids0[0]}"] .name`);
      await page.keyboard.press("Alt+ArrowDown");
      const ids1 = await until(async () => { const ids = (await doc()).placements.map((p) => p.id); return ids[1] === ids0[0] && ids; }, "moved down one");
      assert.equal(ids1[0], ids0[1]);
      assert.equal(ids1.length, ids0.length);
    }],
    ["the activation strip jumps to the clicked time", async () => {
      const box = await page.$eval("#activation", (c) => { const r = c.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
      await page.mouse.click(box[0] + box[2] * 0.9, box[1] + box[3] / 2);
      const t = (await state(page)).time;
      assert.ok(t > 1.5, `time ${t}`);
    }],
    ["the sweep contact sheet opens", async () => {
      await select("elbow_l");
      await page.click("#sweep");
      await page.waitForFunction(() => { const i = document.querySelector("#sweepDialog img"); return i && i.complete && i.naturalWidth > 0; }, null, { timeout: 30000 });
      await screenshot(page, "editor-sweep.png");
      await page.keyboard.press("Escape");
    }],
    ["the bump-map overlay on the texture view", async () => {
      await page.selectOption("#overlay", "bump");
      await until(() => page.evaluate(() => {
        const c = document.getElementById("uv"), d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let warm = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] > 200 && d[i + 1] > 120 && d[i + 1] < 200 && d[i + 2] < 120) ++warm;
        return warm > 200;
      }), "raised skin drawn warm");
      await screenshot(page, "editor-overlay.png");
      await page.selectOption("#overlay", "none");
    }],
    ["every control is labelled and reachable by keyboard", async () => {
      const unlabelled = await page.evaluate(() => {
        const bad = [];
        for (const el of document.querySelectorAll("button, input, select, canvas[tabindex], [tabindex]")) {
          const r = el.getBoundingClientRect();
          if (el.type === "file" || r.width === 0 || r.height === 0 || el.closest("[hidden], dialog:not([open])")) continue;
          const label = el.getAttribute("aria-label") || el.title || (el.labels && el.labels.length && el.labels[0].textContent.trim()) || el.textContent.trim();
          if (!label) bad.push(el.outerHTML.slice(0, 80));
          // A roving list (one tab stop, arrows inside) counts as reachable when it has its stop.
          const roving = el.closest("[data-roving]");
          if (el.tabIndex < 0 && !(roving && roving.querySelector('[tabindex="0"]'))) bad.push("not focusable: " + el.outerHTML.slice(0, 80));
        }
        return bad;
      });
      assert.deepEqual(unlabelled, []);
      // Tab walks from the toolbar into the views and panels; footprints are selected by keys.
      await page.focus("#scene");
      const seen = new Set();
      for (let i = 0; i < 200 && !(seen.has("uv") && seen.has("frameStage")); ++i) { await page.keyboard.press("Tab"); seen.add(await page.evaluate(() => { const e = document.activeElement; return e.id || `${e.tagName}.${e.className}:${(e.getAttribute("aria-label") || e.textContent).slice(0, 20)}`; })); }
      assert.ok(seen.has("uv") && seen.has("frameStage"), `Tab reaches the views: ${[...seen].join(" | ")}`);
      // Few stops on the way: the library and the placements list are one stop each.
      await page.focus("#scene");
      let tabs = 0;
      while (tabs < 200 && await page.evaluate(() => document.activeElement.id) !== "uv") { await page.keyboard.press("Tab"); ++tabs; }
      assert.ok(tabs <= 30, `${tabs} Tabs from the scene menu to the texture view`);
      // No trap: from the texture view, Tab goes on through the 3D view's bar and stage to the
      // parameters and the history (both views shown: the page order).
      const after3d = [];
      for (let i = 0; i < 40 && !after3d.includes("historyList"); ++i) {
        await page.keyboard.press("Tab");
        after3d.push(await page.evaluate(() => { const e = document.activeElement; return e.closest("#historyList") ? "historyList" : e.id || e.tagName; }));
      }
      assert.ok(after3d.includes("viewMode") && after3d.includes("frameStage") && after3d.includes("historyList"),
                `Tab from the texture view reaches the 3D bar, the 3D view and the history: ${after3d.join(" | ")}`);
      // Arrows walk the lists: the library's current pattern and the placement selection follow.
      await page.focus('#libraryList button[tabindex="0"]');
      const before = await page.evaluate(() => document.activeElement.dataset.pattern);
      await page.keyboard.press("ArrowRight");
      const after = await page.evaluate(() => ({ focus: document.activeElement.dataset.pattern, current: document.querySelector("#libraryList button.current").dataset.pattern, stops: document.querySelectorAll('#libraryList [tabindex="0"]').length }));
      assert.notEqual(after.focus, before);
      assert.equal(after.current, after.focus);
      assert.equal(after.stops, 1);
      await page.keyboard.press("ArrowLeft");
      await page.keyboard.press("v");
      assert.equal(await page.evaluate(() => document.activeElement.id), "frameStage", "V goes to the 3D view");
      await page.keyboard.press("l");
      const row0 = await page.evaluate(() => document.activeElement.closest("li")?.dataset.placement);
      assert.ok(row0, "L goes to the placements list");
      const centre0 = (await doc()).placements.find((p) => p.id === row0)?.center;
      await page.keyboard.press("ArrowDown");
      const row1 = await page.evaluate(() => document.activeElement.closest("li")?.dataset.placement);
      assert.ok(row1 && row1 !== row0, "↓ moves to the next row");
      assert.deepEqual((await state(page)).selection, [row1], "and selects it");
      assert.deepEqual((await doc()).placements.find((p) => p.id === row0)?.center, centre0, "arrows in the list nudge nothing");
      await page.keyboard.press("t");
      assert.equal(await page.evaluate(() => document.activeElement.id), "uv", "T goes to the texture view");
      await page.focus("#uv");
      await page.keyboard.press("n");
      assert.equal((await state(page)).selection.length, 1);
    }],
    ["a server error appears on screen", async () => {
      await page.setInputFiles("#loadFile", { name: "broken.scene.json", mimeType: "application/json", buffer: Buffer.from(JSON.stringify({ format: "dermis.scene/1", model: "builtin:default", placements: [{ id: "x", pattern: "crease", joint: "no_such_joint" }] })) });
      await noticeMatching(/no joint named 'no_such_joint'/);
      assert.ok((await doc()).placements.length > 5, "nothing changed");
    }],
  ]);

  // Benchmark: pointer move → new frame on screen while dragging, 512², 100 moves.
  await page.selectOption("#compareMode", "off");
  await page.evaluate(() => { window.dermisEditor.clearTrace(); window.dermisEditor.trace.on = true; });
  await settle();
  const g = await footprint(page, "stomach");
  await page.evaluate(([x0, y0]) => new Promise((resolve) => {
    const c = document.getElementById("uv");
    const ev = (type, x, y) => c.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, button: 0, buttons: 1, pointerId: 9, bubbles: true }));
    ev("pointerdown", x0, y0);
    let i = 0;
    const timer = setInterval(() => {
      ++i;
      ev("pointermove", x0 + (i % 30) - 15, y0 + ((i * 7) % 20) - 10);
      if (i >= 100) { clearInterval(timer); setTimeout(() => { ev("pointerup", x0, y0); resolve(); }, 1500); }
    }, 50);
  }), g.center);
  await sleep(1500);
  const tr = await page.evaluate(() => JSON.parse(JSON.stringify(window.dermisEditor.trace)));
  // A move's latency: until the first frame wanted at or after it (it carries that move's
  // position or a newer one: the drag's preview) is on screen.
  const lat = [];
  for (const m of tr.moves) {
    const f = tr.frames.find((fr) => fr.t0 >= m);
    if (f) lat.push(f.shownAt - m);
  }
  const median = (xs) => { const v = [...xs].sort((x, y) => x - y); return v.length ? +v[Math.floor(v.length / 2)].toFixed(1) : null; };
  const editMs = median(tr.acks.map((x) => x.ackAt - x.sentAt));
  const frameMs = median(tr.frames.map((f) => f.shownAt - f.t0));
  lat.sort((x, y) => x - y);
  const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
  const figures = { benchmark: "editor_drag_to_frame", frame: "512x512", moves: tr.moves.length, measured: lat.length,
                    edits: tr.acks.length, frames: tr.frames.length, edit_p50_ms: editMs, frame_p50_ms: frameMs, p50_ms: +q(0.5).toFixed(1), p95_ms: +q(0.95).toFixed(1),
                    gl: process.env.DERMIS_TEST_GL || "auto" };
  console.log(JSON.stringify(figures));
  writeFileSync(join(shotDir, "editor-drag-bench.json"), JSON.stringify(figures, null, 2) + "\n");
  if (lat.length < 50) { console.log("benchmark: too few moves reached a frame"); ++failures; }
  if (page.errors.length) { console.log("script errors:", page.errors); ++failures; }
  return failures;
}, async () => {
  await browser.close();
  server.stop();
});
