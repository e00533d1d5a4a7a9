// WebEditorUxBrowserTest — what an artist sees and is told, in Debian's Chromium (playwright-core)
// against a real dermis-server on 127.0.0.1.
// Usage: node editor_ux.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the workspace fills a 1920×1080 window even when the scene has no placements, and the
// empty placements list says how to add one; at 1280×720 the toolbar is one row and the views keep
// their room ("against" only while comparing); the save indicator says Saving… / Saved / Not
// saved, and closing the window with an edit on its way asks first; Delete says what it deleted
// and its Undo brings it back selected; the place tool says what a click adds, and Esc leaves it
// without dropping the selection; Ctrl+Z and Redo say what they undid / redid, each with the
// way back; footprint labels never overlap (at 1280×720 and 1920×1080), the selected one always
// shows (clear of its handles), a hidden one shows on hover; Ctrl+= / Ctrl+- / Ctrl+0 zoom and fit the texture view (not
// the page, and only there) and arrows pan it when nothing is selected, all listed by ?; at
// 1280×720 the 3D view bar is one row with Size and Reset in a ⋯ menu that Enter / ↓ opens and
// Esc closes (focus back on ⋯); at 1920×1080 and 1600×1000, in every layout and compare mode, no
// control is cut off at the bar's end (the controls fold into ⋯ exactly where the row does not
// fit; the 3D view alone at 1920 has them in the bar).
// Screenshots: editor-empty.png, editor-1280x720.png, editor-deleted-undo.png,
// editor-place-tool.png, editor-undo-notice.png, editor-labels.png, editor-labels-1920.png,
// editor-3d-more.png.
import assert from "node:assert/strict";
import { startServer, launch, apiClient, openEditor, state, footprint, screenshot, runChecks, runSuite, settled, until, sleep, selectPlacement } from "./editor_lib.mjs";

const server = await startServer(process.argv[2], [], "dermis-editor-ux-");
const api = apiClient(server.base);
const browser = await launch();
await runSuite("WebEditorUxBrowserTest", async () => {
  const context = await browser.newContext();
  const box = (page, sel) => page.$eval(sel, (e) => { const r = e.getBoundingClientRect(); return { top: r.top, bottom: r.bottom, left: r.left, width: r.width, height: r.height }; });
  const visible = (page, sel) => page.$eval(sel, (e) => !e.hidden && e.getBoundingClientRect().height > 0 && getComputedStyle(e).display !== "none");
  // The texture view's key hint is shown whole or not at all (never "1–9 pla…").
  const hintWhole = (page) => page.$eval("#textureView .viewbar .hint", (e) => getComputedStyle(e).display === "none" || e.scrollWidth <= e.clientWidth + 1);
  const hintShown = (page) => page.$eval("#textureView .viewbar .hint", (e) => getComputedStyle(e).display !== "none");
  let page, sceneUrl; // the 1280×720 window on a scene with the default placements (checks 2–6)

  const failures = await runChecks("WebEditorUxBrowserTest", [
    ["1920×1080, no placements: the workspace fills the window and the empty list says what to do", async () => {
      const created = await api("POST", "/scenes", { format: "dermis.scene/1", model: "builtin:default", placements: [] });
      assert.equal(created.status, 201, JSON.stringify(created.body));
      const p = await openEditor(context, `${server.base}/?scene=${created.body.id}`, { width: 1920, height: 1080 });
      const bar = await box(p, ".toolbar"), ws = await box(p, ".workspace"), foot = await box(p, ".timeline");
      assert.ok(Math.abs(foot.bottom - 1080) <= 1, `the timeline ends at the window's bottom (${foot.bottom})`);
      assert.ok(ws.height >= 1080 - bar.height - foot.height - 2, `the workspace takes the rest (${ws.height} px)`);
      assert.ok(await visible(p, "#placementsEmpty"), "the empty placements list shows its hint");
      assert.match(await p.$eval("#placementsEmpty", (e) => e.textContent.replace(/\s+/g, " ")), /No placements yet.*1.*9.*place tool/);
      assert.ok(await hintWhole(p), "the key hint is whole or hidden, never cut");
      await p.click('[data-layout="texture"]');
      await until(async () => await hintShown(p) && await hintWhole(p), "the texture view alone shows its key hint whole");
      await p.click('[data-layout="both"]');
      await screenshot(p, "editor-empty.png");
      // The hint's own advice works: 1 over the texture view adds one, and the hint goes.
      const uv = await box(p, "#uv");
      await p.mouse.move(uv.left + uv.width / 2, uv.top + uv.height / 2);
      await p.keyboard.press("1");
      await until(async () => (await api("GET", `/scenes/${created.body.id}`)).body.scene.placements.length === 1, "a placement from key 1");
      await until(async () => !(await visible(p, "#placementsEmpty")), "the hint hides once there is a placement");
      assert.deepEqual(p.errors, []);
      await p.close();
    }],
    ["1280×720: one toolbar row, short view bars, room for the views", async () => {
      const scene = await api("POST", "/scenes", { default_patterns: true }); // the 18 default placements
      assert.equal(scene.status, 201, JSON.stringify(scene.body));
      sceneUrl = `${server.base}/?scene=${scene.body.id}`;
      page = await openEditor(context, sceneUrl, { width: 1280, height: 720 });
      await sleep(300);
      const bar = await box(page, ".toolbar");
      assert.ok(bar.height < 44, `the toolbar is one row (${bar.height} px)`);
      // Whatever this window's random name and the revision: the longest name the editor makes,
      // and a five-digit revision, still leave one row (a long name wrapped it in one CI run).
      const [name, rev] = await page.evaluate(() => [document.getElementById("me").textContent, document.getElementById("revision").textContent]);
      await page.evaluate(() => { document.getElementById("me").textContent = "nimble-marten-wwww"; document.getElementById("revision").textContent = "r88888"; });
      const longBar = await box(page, ".toolbar");
      assert.ok(longBar.height < 44, `the toolbar is one row with the longest name (${longBar.height} px)`);
      await page.evaluate(([n, r]) => { document.getElementById("me").textContent = n; document.getElementById("revision").textContent = r; }, [name, rev]);
      const tbar = await box(page, "#textureView .viewbar"), fbar = await box(page, "#frameView .viewbar");
      assert.ok(tbar.height < 40, `the texture view bar is one row (${tbar.height} px)`);
      assert.ok(fbar.height < 40, `the 3D view bar is one row too (${fbar.height} px): Size and Reset fold into ⋯`);
      const uv = await box(page, "#uv"), stage = await box(page, "#frameStage");
      assert.ok(uv.height >= 340 && stage.height >= 340, `the views keep their room (${uv.height}, ${stage.height} px)`);
      const foot = await box(page, ".timeline");
      assert.ok(Math.abs(foot.bottom - 720) <= 1 && foot.height <= 240, `the timeline (${foot.height} px) ends at the bottom`);
      assert.ok(await hintWhole(page), "the key hint is whole or hidden, never cut");
      // "against" only means something while comparing.
      assert.equal(await visible(page, "#compareAgainstLabel"), false, "no 'against' while compare is off");
      await page.selectOption("#compareMode", "split");
      assert.equal(await visible(page, "#compareAgainstLabel"), true, "'against' while comparing");
      await page.selectOption("#compareMode", "off");
      await screenshot(page, "editor-1280x720.png");
    }],
    ["1280×720: the 3D view bar's ⋯ menu works by keyboard (Enter opens, Esc closes); wider windows cut nothing off and fold only where the row does not fit", async () => {
      assert.ok(await visible(page, "#viewMore"), "⋯ shows on the narrow 3D view bar");
      assert.equal(await visible(page, "#resetCamera"), false, "Reset is folded into it");
      assert.equal(await page.$eval("#viewMore", (b) => b.getAttribute("aria-expanded")), "false");
      await page.focus("#viewMore");
      await page.keyboard.press("Enter");
      assert.equal(await page.$eval("#viewMore", (b) => b.getAttribute("aria-expanded")), "true", "Enter opens it");
      assert.equal(await page.evaluate(() => document.activeElement.id), "frameSize", "the focus on its first control");
      assert.ok(await visible(page, "#resetCamera"));
      const menu = await box(page, "#viewMoreMenu"), stage = await box(page, "#frameStage");
      assert.ok(menu.left + menu.width <= 1280 && menu.top >= stage.top - 40, "the menu opens under the bar, inside the window");
      await screenshot(page, "editor-3d-more.png");
      await page.keyboard.press("Tab");
      assert.equal(await page.evaluate(() => document.activeElement.id), "placeAs", "Tab reaches Place as");
      await page.keyboard.press("Tab");
      assert.equal(await page.evaluate(() => document.activeElement.id), "resetCamera", "Tab reaches Reset");
      await page.evaluate(() => window.dermisEditor.store.camera.yaw = 77);
      await page.keyboard.press("Enter");
      await until(async () => (await state(page)).camera.yaw === 0, "Enter on Reset resets the camera");
      const selection = (await state(page)).selection;
      await page.keyboard.press("Escape");
      assert.equal(await page.$eval("#viewMore", (b) => b.getAttribute("aria-expanded")), "false", "Esc closes it");
      assert.equal(await page.evaluate(() => document.activeElement.id), "viewMore", "and gives the focus back to ⋯");
      assert.deepEqual((await state(page)).selection, selection, "that Esc only closes the menu");
      assert.equal(await visible(page, "#resetCamera"), false);
      // ↓ opens it too; Tab past its last control closes it.
      await page.keyboard.press("ArrowDown");
      assert.equal(await page.evaluate(() => document.activeElement.id), "frameSize");
      for (let i = 0; i < 6 && await page.evaluate(() => !!document.activeElement.closest("#viewMoreMenu")); ++i) await page.keyboard.press("Tab");
      assert.equal(await page.evaluate(() => !!document.activeElement.closest("#viewMoreMenu")), false, "Tab leaves the menu");
      assert.equal(await page.$eval("#viewMore", (b) => b.getAttribute("aria-expanded")), "false", "leaving the menu closes it");
      // Wider windows: whatever the layout, window and compare mode, no control is cut off at
      // the bar's end (at 1920×1080 side by side, Frame and Turntable were, past the 684 px bar);
      // where the row fits, ⋯ is hidden and the controls sit in the bar.
      const cut = (pg) => pg.$eval("#frameView .viewbar", (bar) => {
        const r = bar.getBoundingClientRect();
        return [...bar.querySelectorAll("button, select, input")].filter((e) => e.getClientRects().length > 0 && e.getBoundingClientRect().right > r.right + 0.5).map((e) => e.id);
      });
      const frames = (pg) => pg.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      const wide = await openEditor(context, sceneUrl, { width: 1920, height: 1080 });
      for (const [layout, compare] of [["both", "off"], ["both", "split"], ["3d", "off"], ["3d", "split"], ["3d", "diff"]]) {
        await wide.click(`[data-layout="${layout}"]`);
        await wide.selectOption("#compareMode", compare);
        await frames(wide);
        assert.deepEqual(await cut(wide), [], `nothing cut off at 1920×1080, ${layout}, compare ${compare}`);
        assert.ok((await box(wide, "#frameView .viewbar")).height < 40, `one row (${layout}, compare ${compare})`);
        const folded = await visible(wide, "#viewMore");
        assert.equal(await visible(wide, "#turntable"), !folded, `Turntable in the row exactly when there is no ⋯ (${layout}, compare ${compare})`);
        if (layout === "3d" && compare === "off") {
          assert.equal(folded, false, "no ⋯ where the bar has room");
          assert.ok(await visible(wide, "#resetCamera") && await visible(wide, "#frameSize"), "Size and Reset sit in the bar");
        }
      }
      await wide.setViewportSize({ width: 1600, height: 1000 }); // the 3D view alone, comparing: 1,049 px
      await frames(wide);
      assert.deepEqual(await cut(wide), [], "nothing cut off at 1600×1000, 3d, compare diff");
      await wide.selectOption("#compareMode", "off");
      await wide.click('[data-layout="both"]');
      await wide.close();
      assert.deepEqual(page.errors, []);
    }],
    ["the save indicator: Saving… while an edit is on its way, Saved after, Not saved when refused", async () => {
      await settled(page, api);
      assert.equal(await page.$eval("#saveState", (e) => e.dataset.state), "saved");
      assert.match(await page.$eval("#saveState", (e) => e.textContent), /Saved/);
      assert.equal(await page.$eval("#saveState", (e) => e.getAttribute("role")), "status");
      let release;
      const gate = new Promise((r) => { release = r; });
      await page.route("**/api/v1/scenes/*/placements/*", async (route) => {
        if (route.request().method() === "PATCH") await gate;
        await route.continue();
      });
      await selectPlacement(page, "elbow_l");
      await page.focus("#uv");
      await page.keyboard.press("]");
      await until(() => page.$eval("#saveState", (e) => e.dataset.state === "saving" && /Saving/.test(e.textContent)), "Saving… while the edit is held");
      release();
      await until(() => page.$eval("#saveState", (e) => e.dataset.state === "saved"), "Saved once the server answered");
      await page.unroute("**/api/v1/scenes/*/placements/*");
      // A refused edit (a document naming a joint the model lacks) leaves "Not saved".
      await page.setInputFiles("#loadFile", { name: "broken.scene.json", mimeType: "application/json", buffer: Buffer.from(JSON.stringify({ format: "dermis.scene/1", model: "builtin:default", placements: [{ id: "x", pattern: "crease", joint: "no_such_joint" }] })) });
      await until(() => page.$eval("#saveState", (e) => e.dataset.state === "error" && /Not saved/.test(e.textContent) && /no_such_joint/.test(e.title)), "Not saved, with the reason in its title");
      await page.focus("#uv");
      await page.keyboard.press("[");
      await until(() => page.$eval("#saveState", (e) => e.dataset.state === "saved"), "Saved again after a good edit");
    }],
    ["closing the window while an edit is on its way asks first", async () => {
      const p = await openEditor(context, sceneUrl, { width: 1280, height: 720 });
      await p.route("**/api/v1/scenes/*/placements/*", () => {}); // never answered
      await selectPlacement(p, "elbow_l");
      await p.focus("#uv");
      await p.keyboard.press("]");
      await until(() => p.$eval("#saveState", (e) => e.dataset.state === "saving"), "an edit on its way");
      const asked = new Promise((resolve) => p.once("dialog", async (d) => { resolve(d.type()); await d.accept(); }));
      await p.close({ runBeforeUnload: true });
      assert.equal(await Promise.race([asked, sleep(5000).then(() => "no dialog")]), "beforeunload");
    }],
    ["Delete says what it deleted; its Undo brings the placement back, selected", async () => {
      await settled(page, api);
      const before = (await api("GET", `/scenes/${(await state(page)).sceneId}`)).body.scene;
      await selectPlacement(page, "knee_l");
      await page.focus("#uv");
      await page.keyboard.press("Delete");
      const undoButton = await page.waitForSelector('#notices .notice:has-text("Deleted \\"knee_l\\"") button.action', { timeout: 10000 });
      assert.equal(await undoButton.textContent(), "Undo");
      await until(async () => !(await api("GET", `/scenes/${before.id || (await state(page)).sceneId}`)).body.scene.placements.some((p) => p.id === "knee_l"), "knee_l gone on the server");
      await screenshot(page, "editor-deleted-undo.png");
      await undoButton.click();
      const id = (await state(page)).sceneId;
      await until(async () => (await api("GET", `/scenes/${id}`)).body.scene.placements.some((p) => p.id === "knee_l"), "knee_l back on the server");
      const after = (await api("GET", `/scenes/${id}`)).body.scene;
      assert.deepEqual(after.placements, before.placements, "the very same placements, in the same order");
      await until(async () => (await state(page)).selection.join() === "knee_l", "knee_l selected again");
    }],
    ["the place tool says what a click adds; Esc leaves it and keeps the selection", async () => {
      await selectPlacement(page, "elbow_r");
      await page.focus("#frameStage");
      assert.equal(await visible(page, "#placeHint"), false);
      await page.keyboard.press("p");
      assert.equal(await page.$eval("#placeTool", (b) => b.getAttribute("aria-pressed")), "true");
      assert.ok(await visible(page, "#placeHint"), "the hint shows with the tool on");
      const current = await page.$eval("#libraryList button.current", (b) => b.dataset.pattern);
      const name = (await api("GET", "/patterns")).body.patterns.find((p) => p.id === current).name;
      assert.match(await page.$eval("#placeHint", (e) => e.textContent), new RegExp(`"${name}".*Esc`));
      // Choosing another pattern changes what the hint promises.
      const other = await page.$eval("#libraryList button:not(.current)", (b) => b.dataset.pattern);
      await page.click(`#libraryList button[data-pattern="${other}"]`);
      const otherName = (await api("GET", "/patterns")).body.patterns.find((p) => p.id === other).name;
      assert.match(await page.$eval("#placeHint", (e) => e.textContent), new RegExp(`"${otherName}"`));
      await screenshot(page, "editor-place-tool.png");
      await page.focus("#frameStage");
      await page.keyboard.press("Escape");
      assert.equal(await page.$eval("#placeTool", (b) => b.getAttribute("aria-pressed")), "false", "Esc leaves the place tool");
      assert.equal(await visible(page, "#placeHint"), false);
      assert.deepEqual((await state(page)).selection, ["elbow_r"], "the first Esc keeps the selection");
      await page.keyboard.press("Escape");
      assert.deepEqual((await state(page)).selection, [], "the next Esc clears it");
      assert.deepEqual(page.errors, []);
    }],
    ["Ctrl+Z says what it undid, with Redo; Redo says what it redid, with Undo", async () => {
      await settled(page, api);
      const id = (await state(page)).sceneId;
      const rotation = async () => (await api("GET", `/scenes/${id}`)).body.scene.placements.find((p) => p.id === "thigh_l").rotation;
      const r0 = await rotation();
      await selectPlacement(page, "thigh_l");
      await page.focus("#uv");
      await page.keyboard.press("]");
      await until(async () => (await rotation()) !== r0, "rotated on the server");
      const r1 = await rotation();
      await settled(page, api);
      await page.keyboard.press("Control+z");
      const redo = await page.waitForSelector(`#notices .notice:has-text('Undone: rotate "thigh_l"') button.action`, { timeout: 10000 });
      assert.equal(await redo.textContent(), "Redo");
      await until(async () => (await rotation()) === r0, "the rotation undone on the server");
      await redo.click();
      await until(async () => (await rotation()) === r1, "redone by the notice's button");
      const again = await page.waitForSelector(`#notices .notice:has-text('Redone: rotate "thigh_l"') button.action`, { timeout: 10000 });
      assert.equal(await again.textContent(), "Undo");
      assert.equal(await page.$$eval('#notices .notice[data-key="undo"]', (n) => n.length), 1, "one undo notice at a time");
      // Someone else on the scene (the window closed above is still shown for a while, or a new
      // one): their chip must not wrap the 1280-px toolbar.
      const other = await openEditor(context, sceneUrl, { width: 1280, height: 720 });
      await until(() => page.$eval("#people", (e) => e.children.length > 0), "another person's chip");
      assert.ok((await box(page, ".toolbar")).height < 44, "still one toolbar row with someone else on the scene");
      await other.close();
      await screenshot(page, "editor-undo-notice.png");
      assert.deepEqual(page.errors, []);
    }],
    ["footprint labels never overlap; the selected one always shows, a hidden one on hover", async () => {
      const labels = (p) => p.evaluate(() => window.dermisEditor.labelLayout());
      const overlaps = (shown) => {
        const bad = [];
        for (let i = 0; i < shown.length; ++i) for (let j = i + 1; j < shown.length; ++j) {
          const a = shown[i], b = shown[j];
          if (a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h) bad.push(`${a.id}/${b.id}`);
        }
        return bad;
      };
      const ids = (await state(page)).doc.placements.map((p) => p.id);
      await page.focus("#uv");
      await page.keyboard.press("Escape");
      await page.keyboard.press("0");
      await sleep(150);
      let l = await labels(page);
      assert.deepEqual(overlaps(l.shown), [], "no two labels overlap at 1280×720");
      assert.deepEqual([...l.shown.map((b) => b.id), ...l.hidden].sort(), [...ids].sort(), "every placement's label is laid out (shown or hidden)");
      assert.ok(l.shown.length >= ids.length / 2, `most labels show (${l.shown.length} of ${ids.length})`);
      // The crowded middle of the default scene: each of them, selected, shows its label.
      for (const id of ["ribs_l", "stomach", "waist_l", "waist_r"]) {
        await selectPlacement(page, id);
        // The layout drawn for this selection (it is drawn on the next animation frame).
        l = await until(async () => { const x = await labels(page); return x.selection === id && x.shown.some((b) => b.id === id) && x; }, `${id}'s label shows when selected`);
        assert.deepEqual(overlaps(l.shown), [], `no overlap with ${id} selected`);
        // No label covers the selection's handles (corners, the rotation handle).
        const g = await footprint(page, id);
        const covered = l.shown.filter((b) => [...g.corners, g.rotate].some(([x, y]) => x > b.x - 4 && x < b.x + b.w + 4 && y > b.y - 4 && y < b.y + b.h + 4));
        assert.deepEqual(covered.map((b) => b.id), [], `labels clear of ${id}'s handles`);
      }
      await screenshot(page, "editor-labels.png");
      // A hidden label shows while its placement is hovered.
      await page.focus("#uv");
      await page.keyboard.press("Escape");
      await sleep(150);
      l = await labels(page);
      let hovered = null;
      for (const id of l.hidden) {
        const g = await footprint(page, id);
        await page.mouse.move(g.center[0], g.center[1]);
        if (await page.$eval("#uv", (c) => c.title.split("\n")[0]) === id) { hovered = id; break; }
      }
      if (l.hidden.length) {
        assert.ok(hovered, `one of the hidden labels' placements can be hovered (${l.hidden.join(", ")})`);
        await until(async () => (await labels(page)).shown.some((b) => b.id === hovered), `${hovered}'s label shows on hover`);
        assert.deepEqual(overlaps((await labels(page)).shown), [], "no overlap while hovering");
      }
      await page.mouse.move(5, 5);
      // A big window: the same, with room for (nearly) every label.
      const big = await openEditor(context, sceneUrl, { width: 1920, height: 1080 });
      await sleep(300);
      const lb = await labels(big);
      assert.deepEqual(overlaps(lb.shown), [], "no two labels overlap at 1920×1080");
      assert.ok(lb.shown.length >= l.shown.length, `at least as many labels at 1920×1080 (${lb.shown.length})`);
      await screenshot(big, "editor-labels-1920.png");
      assert.deepEqual(big.errors, []);
      await big.close();
    }],
    ["keyboard zoom and pan in the texture view: Ctrl+= / Ctrl+- / Ctrl+0, arrows with nothing selected", async () => {
      await settled(page, api);
      const rev = (await state(page)).revision;
      await page.evaluate(() => { window.__prevented = []; window.addEventListener("keydown", (e) => window.__prevented.push(e.defaultPrevented)); });
      const prevented = () => page.evaluate(() => window.__prevented[window.__prevented.length - 1]);
      await page.focus("#uv");
      await page.keyboard.press("Escape");
      await page.keyboard.press("0");
      const g0 = await footprint(page, "stomach");
      await page.keyboard.press("Control+Equal");
      assert.equal(await prevented(), true, "Ctrl+= in the texture view is not the browser's page zoom");
      const g1 = await footprint(page, "stomach");
      assert.ok(Math.abs(g1.pxPerUV / g0.pxPerUV - 1.25) < 1e-6, `Ctrl+= zooms in 25% (${g0.pxPerUV} → ${g1.pxPerUV})`);
      await until(() => page.$eval("#zoomText", (e) => e.textContent === `${Math.round(0.94 * 1.25 * 100)}%`), "the zoom badge follows");
      await page.keyboard.press("Control+Minus");
      await page.keyboard.press("Control+Minus");
      const g2 = await footprint(page, "stomach");
      assert.ok(Math.abs(g2.pxPerUV * 1.25 / g0.pxPerUV - 1) < 1e-6, "Ctrl+- zooms out");
      // Arrows with nothing selected pan (the view moves, the footprints the other way).
      await page.keyboard.press("ArrowRight");
      const g3 = await footprint(page, "stomach");
      assert.ok(Math.abs(g3.center[0] - (g2.center[0] - 40)) < 0.01 && Math.abs(g3.center[1] - g2.center[1]) < 0.01, "→ pans 40 px");
      await page.keyboard.press("Shift+ArrowUp");
      const g4 = await footprint(page, "stomach");
      assert.ok(Math.abs(g4.center[1] - (g3.center[1] + 200)) < 0.01, "Shift+↑ pans 200 px");
      await page.keyboard.press("Control+0");
      assert.equal(await prevented(), true, "Ctrl+0 in the texture view fits it");
      const g5 = await footprint(page, "stomach");
      assert.ok(Math.abs(g5.pxPerUV - g0.pxPerUV) < 1e-6 && Math.abs(g5.center[0] - g0.center[0]) < 0.01, "Ctrl+0 fits again");
      await sleep(300);
      assert.equal((await state(page)).revision, rev, "zoom and pan edit nothing");
      // Outside the texture view the browser keeps its page zoom keys.
      await page.focus('#placementList button[tabindex="0"]');
      await page.keyboard.press("Control+Equal");
      assert.equal(await prevented(), false, "Ctrl+= outside the texture view is left to the browser");
      // ? lists them.
      await page.focus("#uv");
      await page.keyboard.press("?");
      const help = await page.$eval("#help", (d) => d.open && d.textContent);
      assert.match(help, /Ctrl\+=.*zoom the texture view/s);
      assert.match(help, /nothing selected, pan the texture view/);
      await page.keyboard.press("Escape");
      assert.deepEqual(page.errors, []);
    }],
  ]);
  return failures;
}, async () => {
  await browser.close();
  server.stop();
});
