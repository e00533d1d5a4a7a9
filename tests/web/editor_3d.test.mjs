// WebEditor3dBrowserTest — the 3D view you can work in, in Debian's Chromium (playwright-core)
// against a real dermis-server on 127.0.0.1.
// Usage: node editor_3d.test.mjs <dermis-server executable>   (exit 0 = pass)
// Checks: the selection is outlined on the skin (frame `highlight`; the frame without it is the
// plain frame, byte for byte) and hovering a placement outlines it (`hover`); the place tool shows
// its brush (`surface_brush`: a circle on the body; `brush` with Place as: in the texture); F frames the selection (camera target = the placement's surface point,
// closer); a drag orbits about the selection (its surface point keeps its pixel); Shift+drag and
// middle drag pan (the picture follows the pointer); the wheel zooms to the cursor (the skin under
// the pointer stays under it); the permalink carries the target and reproduces the frame byte for
// byte; the sweep dialog uses the camera and zooms to the placement; the turntable button opens
// an animated WebP of the selection; the compare menu is labelled "Compare" and the bar is one row
// in every compare mode at 1600×1000 and 1280×720.
// Screenshots: editor-3d-1600x1000.png, editor-3d-1280x720.png (a framed, highlighted selection),
// editor-3d-hover.png, editor-3d-brush.png, editor-3d-diff-1280.png, editor-3d-turntable.png,
// editor-3d-sweep-zoom.png.
import assert from "node:assert/strict";
import { createHash } from "node:crypto";
import { startServer, launch, apiClient, openEditor, state, screenshot, runChecks, runSuite, until, sleep, settledFrameHash, holdAnswers } from "./editor_lib.mjs";

const server = await startServer(process.argv[2], [], "dermis-editor-3d-");
const api = apiClient(server.base);
const browser = await launch();

// The camera maths of core/camera.hpp (30° field of view, square frames): a world point's frame
// pixel for a camera {yaw, pitch, distance, target} and a frame of `size` pixels.
function project(cam, p, size) {
  const rad = Math.PI / 180, y = cam.yaw * rad, x = cam.pitch * rad;
  const dir = [Math.sin(y) * Math.cos(x), Math.sin(x), Math.cos(y) * Math.cos(x)];
  const up0 = Math.abs(dir[1]) > 0.999 ? [0, 0, -dir[1]] : [0, 1, 0];
  const f = dir.map((c) => -c);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const n = (a) => { const l = Math.hypot(...a); return a.map((c) => c / l); };
  const right = n(cross(f, up0)), up = cross(right, f);
  const eye = cam.target.map((c, i) => c + dir[i] * cam.distance);
  const d = p.map((c, i) => c - eye[i]);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = dot(d, f), t = Math.tan(15 * rad);
  return [(dot(d, right) / (z * t) + 1) * size / 2, (1 - dot(d, up) / (z * t)) * size / 2];
}

await runSuite("WebEditor3dBrowserTest", async () => {
  const context = await browser.newContext();
  const created = await api("POST", "/scenes", { default_patterns: true });
  assert.equal(created.status, 201, JSON.stringify(created.body));
  const sceneId = created.body.id;
  const page = await openEditor(context, `${server.base}/?scene=${sceneId}`, { width: 1600, height: 1000 });
  await page.click('[data-layout="3d"]');
  const frameUrl = () => page.evaluate(() => window.dermisEditor.frameUrl());
  const param = async (name) => new URL("http://x/api/v1" + await frameUrl()).searchParams.get(name);
  const camera = async () => (await state(page)).camera;
  const frameBox = async () => {
    const b = await page.$eval("#frame", (i) => { const r = i.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
    const side = Math.min(b[2], b[3]);
    return { x0: b[0] + (b[2] - side) / 2, y0: b[1] + (b[3] - side) / 2, side };
  };
  const size = () => page.evaluate(async () => (await import("/js/frame_view.js")).frameParams().width);
  // Client coordinates of a frame pixel.
  const client = async (px) => { const b = await frameBox(), n = await size(); return [b.x0 + (px[0] + 0.5) / n * b.side, b.y0 + (px[1] + 0.5) / n * b.side]; };
  const fetchBytes = async (url) => Buffer.from((await api("GET", url.replace(/^\/api\/v1/, ""))).body);
  const hash = (b) => createHash("sha256").update(b).digest("hex");
  // A frame pixel on the skin of placement `id` (the editor's own pick), searched on a grid.
  const pixelOn = (id) => page.evaluate(async (pid) => {
    const ed = window.dermisEditor, doc = ed.store.doc, n = (await import("/js/frame_view.js")).frameParams().width;
    const p = doc.placements.find((q) => q.id === pid);
    const inside = (uv) => {
      const a = (p.rotation * Math.PI) / 180, c = Math.cos(a), s = Math.sin(a);
      const dx = uv[0] - p.center[0], dy = uv[1] - p.center[1];
      const x = (c * dx + s * dy) / p.scale[0] + 0.5, y = (-s * dx + c * dy) / p.scale[1] + 0.5;
      return x >= 0.25 && x <= 0.75 && y >= 0.25 && y <= 0.75;
    };
    for (let y = Math.floor(n * 0.15); y < n * 0.9; y += Math.floor(n / 40))
      for (let x = Math.floor(n * 0.2); x < n * 0.8; x += Math.floor(n / 40)) {
        const hit = await ed.pickAt(x, y);
        if (hit.hit && inside(hit.uv)) return { px: [x, y], hit };
      }
    return null;
  }, id);
  // GET focus at the time the editor shows (the default scene is posed mid-clip).
  const focusOf = async (pid) => {
    const t = await page.evaluate(async () => (await import("/js/frame_view.js")).frameParams().time);
    return (await api("GET", `/scenes/${sceneId}/focus?placement=${pid}&time=${t}`)).body;
  };
  const closeDialogs = () => page.evaluate(() => document.querySelectorAll("dialog[open]").forEach((d) => d.close()));

  const failures = await runChecks("WebEditor3dBrowserTest", [
    ["the selection is outlined on the skin; without a selection the frame is the plain one", async () => {
      const plainHash = await settledFrameHash(page);
      assert.equal(await param("highlight"), null);
      await page.evaluate(async () => { const m = await import("/js/store.js"); m.set({ selection: ["stomach"] }); });
      await until(async () => (await param("highlight")) === "stomach", "the frame asks for highlight=stomach");
      const hiHash = await settledFrameHash(page);
      assert.notEqual(hiHash, plainHash, "the outline changes the frame");
      // The same URL without highlight is the plain frame, byte for byte.
      const url = await frameUrl();
      const without = url.replace(/&?highlight=[^&]*/, "");
      assert.equal(hash(await fetchBytes("/api/v1" + without)), plainHash);
    }],
    ["F frames the selection: the target is the placement's surface point, the camera closer", async () => {
      const before = await camera();
      await page.focus("#frameStage");
      await page.keyboard.press("f");
      const cam = await until(async () => { const c = await camera(); return c.target && c; }, "F set a target");
      const focus = (await focusOf("stomach"));
      assert.deepEqual(cam.target.map((x) => +x.toFixed(3)), focus.target.map((x) => +x.toFixed(3)), JSON.stringify({ cam, focus }));
      assert.ok(cam.distance < 0.6 * (before.distance ?? 1e9) || before.distance === null, "closer");
      assert.equal(await param("target"), cam.target.join(","));
      await settledFrameHash(page);
      await screenshot(page, "editor-3d-1600x1000.png");
    }],
    ["a drag orbits about the selection: its surface point keeps its pixel", async () => {
      // Move the target off the selection first (pan), so that orbiting about it is not trivially the target.
      const n = await size();
      const c0 = await camera();
      await page.evaluate(async () => { const m = await import("/js/camera3d.js"); m.panBy(60, -30, 512); });
      const c1 = await until(async () => { const c = await camera(); return c.target.join() !== c0.target.join() && c; }, "panned");
      const focus = (await focusOf("stomach"));
      const p1 = project(c1, focus.target, n);
      const [cx, cy] = await client([n * 0.5, n * 0.5]);
      await page.mouse.move(cx, cy);
      await page.mouse.down();
      for (let k = 1; k <= 8; ++k) await page.mouse.move(cx + k * 10, cy + k * 3);
      await page.mouse.up();
      const c2 = await until(async () => { const c = await camera(); return c.yaw !== c1.yaw && c; }, "orbited");
      const p2 = project(c2, focus.target, n);
      assert.ok(Math.hypot(p2[0] - p1[0], p2[1] - p1[1]) < 1.5, `the pivot stays at its pixel: ${p1} → ${p2} ${JSON.stringify({ c1, c2, focus })}`);
      assert.notDeepEqual(c2.target, c1.target, "the target turned about the pivot");
    }],
    ["Shift+drag and middle drag pan: the picture follows the pointer", async () => {
      const n = await size();
      const c0 = await camera();
      const [cx, cy] = await client([n * 0.5, n * 0.5]);
      const b = await frameBox();
      await page.keyboard.down("Shift");
      await page.mouse.move(cx, cy);
      await page.mouse.down();
      await page.mouse.move(cx + 40, cy + 10, { steps: 4 });
      await page.mouse.up();
      await page.keyboard.up("Shift");
      const c1 = await until(async () => { const c = await camera(); return c.target.join() !== c0.target.join() && c; }, "Shift+drag moved the target");
      assert.equal(c1.yaw, c0.yaw);
      assert.equal(c1.pitch, c0.pitch);
      // The old target moved on screen by the drag (40, 10) css px.
      const p = project(c1, c0.target, n);
      const moved = [(p[0] - n / 2) * b.side / n, (p[1] - n / 2) * b.side / n];
      assert.ok(Math.abs(moved[0] - 40) < 2 && Math.abs(moved[1] - 10) < 2, `follows the pointer: ${moved}`);
      await page.mouse.move(cx, cy);
      await page.mouse.down({ button: "middle" });
      await page.mouse.move(cx - 30, cy, { steps: 3 });
      await page.mouse.up({ button: "middle" });
      await until(async () => (await camera()).target.join() !== c1.target.join(), "middle drag panned");
    }],
    ["the wheel zooms to the cursor: the skin under the pointer stays under it", async () => {
      const n = await size();
      await settledFrameHash(page);
      const on = await pixelOn("stomach") || await pixelOn("waist_l");
      assert.ok(on, "a pixel on the skin");
      const [x, y] = await client(on.px);
      await page.mouse.move(x, y);
      // The hover pick of this very pixel (not an earlier one still landing: slow under ASan).
      await until(async () => page.evaluate(async (px) => {
        const m = await import("/js/camera3d.js");
        const last = m.pointer.last;
        return !!(last && last.hit && Math.hypot(last.px[0] - px[0], last.px[1] - px[1]) <= 3);
      }, on.px), "the hover pick of the pixel under the pointer landed");
      const c0 = await camera();
      await page.mouse.wheel(0, -200);
      const c1 = await until(async () => { const c = await camera(); return c.distance < c0.distance && c; }, "zoomed in");
      const p0 = project(c0, on.hit.position, n), p1 = project(c1, on.hit.position, n);
      assert.ok(Math.hypot(p1[0] - p0[0], p1[1] - p0[1]) < 2.5, `the point under the cursor stays: ${p0} → ${p1}`);
      assert.notDeepEqual(c1.target, c0.target, "the target moved towards the cursor");
    }],
    ["a wheel tick right after a pick answered for the camera before the last tick still keeps the skin under the pointer", async () => {
      // Picks answer 1.5 s late: the pointer's pick (camera 0) lands after tick A moved the camera;
      // tick B must zoom about the skin under the pointer now, not about that pick's point (which
      // shows elsewhere after tick A: zooming about it drifts the picture under the pointer).
      const n = await size();
      await settledFrameHash(page);
      const far = await page.evaluate(async () => {
        const ed = window.dermisEditor, n = (await import("/js/frame_view.js")).frameParams().width;
        let best = null;
        for (let y = Math.floor(n * 0.1); y < n * 0.9; y += Math.floor(n / 16))
          for (let x = Math.floor(n * 0.1); x < n * 0.9; x += Math.floor(n / 16)) {
            const d = Math.hypot(x - n / 2, y - n / 2);
            if (best && d <= best.d) continue;
            const hit = await ed.pickAt(x, y);
            if (hit.hit) best = { px: [x, y], d };
          }
        return best;
      });
      assert.ok(far && far.d > n * 0.15, `a pixel on the skin off the centre (${JSON.stringify(far)})`);
      const slow = await holdAnswers(page, (url) => url.pathname.endsWith("/pick"), { ms: 1500 });
      const [x, y] = await client(far.px);
      await page.mouse.move(x, y);
      await sleep(100);
      const c0 = await camera();
      await page.mouse.wheel(0, -200); // tick A: no pick at this pixel yet: about the target
      const cA = await until(async () => { const c = await camera(); return c.distance < c0.distance && c; }, "tick A zoomed");
      await until(() => page.evaluate((px) => import("/js/camera3d.js").then((m) => {
        const last = m.pointer.last;
        return !!(last && last.hit && Math.hypot(last.px[0] - px[0], last.px[1] - px[1]) <= 3);
      }), far.px), "the pointer's pick (made before tick A) landed", 30000);
      // The skin under the pointer with tick A's camera, asked directly (not held).
      const p = await page.evaluate((px) => import("/js/frame_view.js").then((m) => ({ ...m.frameParams(), x: px[0], y: px[1] })), far.px);
      const q = new URLSearchParams();
      for (const k of ["x", "y", "width", "height", "yaw", "pitch", "distance", "target", "time"]) if (p[k] !== undefined) q.set(k, p[k]);
      const under = (await api("GET", `/scenes/${sceneId}/pick?${q}`)).body;
      assert.ok(under.hit, "skin under the pointer after tick A");
      await page.mouse.wheel(0, -200); // tick B, before the pick with tick A's camera answers
      const cB = await until(async () => { const c = await camera(); return c.distance < cA.distance && c; }, "tick B zoomed");
      await slow.stop();
      const pA = project(cA, under.position, n), pB = project(cB, under.position, n);
      assert.ok(Math.hypot(pB[0] - pA[0], pB[1] - pA[1]) < 2.5, `the skin under the pointer stays: ${pA} → ${pB}`);
    }],
    ["hovering a placement outlines it; the place tool shows its brush", async () => {
      await page.evaluate(async () => { const m = await import("/js/store.js"); m.set({ selection: [] }); });
      await page.click("#resetCamera").catch(async () => { await page.click("#viewMore"); await page.click("#resetCamera"); });
      await settledFrameHash(page);
      const on = await pixelOn("stomach");
      assert.ok(on, "a pixel on the stomach");
      const [x, y] = await client(on.px);
      await page.mouse.move(x - 3, y);
      await page.mouse.move(x, y);
      await until(async () => (await param("hover")) === "stomach", "hover=stomach");
      await settledFrameHash(page);
      await screenshot(page, "editor-3d-hover.png");
      await page.click("#placeTool");
      await page.mouse.move(x + 2, y + 1);
      // The brush on the body (a circle: surface_brush, what a click adds by default) …
      const brush = await until(async () => param("surface_brush"), "a surface brush in the frame URL");
      const b = brush.split(",").map(Number);
      assert.equal(b.length, 7);
      assert.ok(b[6] > 0, brush);
      assert.equal(await param("brush"), null);
      await settledFrameHash(page);
      await screenshot(page, "editor-3d-brush.png");
      // … or, placing in the texture, the UV footprint a click adds.
      const placeAs = (v) => page.evaluate((value) => { const s = document.getElementById("placeAs"); s.value = value; s.dispatchEvent(new Event("change")); }, v);
      await placeAs("uv");
      await page.mouse.move(x + 1, y + 1);
      await page.mouse.move(x + 2, y + 1);
      const uvBrush = await until(async () => param("brush"), "a UV brush in the frame URL");
      const ub = uvBrush.split(",").map(Number);
      assert.equal(ub.length, 5);
      assert.ok(Math.abs(ub[2] - 0.08) < 1e-9 && Math.abs(ub[3] - 0.08) < 1e-9, uvBrush);
      assert.equal(await param("surface_brush"), null);
      await placeAs("surface");
      await page.keyboard.press("p");
      await until(async () => (await param("brush")) === null && (await param("surface_brush")) === null, "no brush once the tool is off");
      await page.mouse.move(5, 5); // leaves the stage: no hover
      await until(async () => (await param("hover")) === null, "no hover outside");
    }],
    ["the permalink carries the target and reproduces the frame byte for byte", async () => {
      await page.evaluate(async () => { const m = await import("/js/store.js"); m.set({ selection: ["elbow_l"] }); });
      await page.focus("#frameStage");
      await page.keyboard.press("F");
      await until(async () => (await param("target")) !== null, "a target");
      const h1 = await settledFrameHash(page);
      // The address bar follows after 150 ms (a page timer, late on a loaded machine).
      const link = await until(() => page.evaluate(async () => { const m = await import("/js/permalink.js"); return location.href === m.currentLink() && location.href; }), "the address bar follows");
      assert.match(link, /target=/);
      const other = await openEditor(context, link, { width: 1600, height: 1000 });
      await other.click('[data-layout="3d"]');
      assert.equal(await settledFrameHash(other), h1, "the same frame");
      assert.deepEqual((await state(other)).camera.target, (await camera()).target);
      await other.close();
    }],
    ["the sweep dialog uses the camera and zooms to the placement", async () => {
      const cam = await camera();
      await page.evaluate(async () => { const m = await import("/js/sweep_view.js"); m.openSweep(window.dermisEditor.store.doc.placements.find((p) => p.id === "elbow_l")); });
      const src = await page.waitForFunction(() => { const i = document.querySelector("#sweepDialog img"); return i && i.complete && i.naturalWidth > 0 && i.src; }, null, { timeout: 60000 });
      const u = new URL(await src.jsonValue());
      assert.equal(+u.searchParams.get("yaw"), cam.yaw, u.href);
      assert.equal(u.searchParams.get("target"), cam.target.join(","), u.href);
      await page.click("#sweepZoom");
      const zoomed = await page.waitForFunction((old) => { const i = document.querySelector("#sweepDialog img"); return i && i.src !== old && i.complete && i.naturalWidth > 0 && i.src; }, u.href, { timeout: 60000 });
      const z = new URL(await zoomed.jsonValue());
      const focus = (await focusOf("elbow_l"));
      assert.equal(z.searchParams.get("size"), "256", "larger cells");
      assert.deepEqual(z.searchParams.get("target").split(",").map((x) => +(+x).toFixed(3)), focus.target.map((x) => +x.toFixed(3)));
      await screenshot(page, "editor-3d-sweep-zoom.png");
      await closeDialogs();
    }],
    ["the turntable button opens an animated WebP of the selection's range of motion", async () => {
      await closeDialogs();
      if (await page.isVisible("#viewMore")) await page.click("#viewMore");
      assert.equal(await page.$eval("#turntable", (b) => b.disabled), false);
      await page.click("#turntable");
      const src = await page.waitForFunction(() => { const i = document.querySelector("#turntableDialog img"); return i && i.complete && i.naturalWidth > 0 && i.src; }, null, { timeout: 120000 });
      const bytes = await fetchBytes(new URL(await src.jsonValue()).pathname + new URL(await src.jsonValue()).search);
      assert.equal(bytes.subarray(0, 4).toString(), "RIFF");
      assert.equal(bytes.subarray(8, 12).toString(), "WEBP");
      assert.ok(bytes.includes(Buffer.from("ANIM")) && bytes.includes(Buffer.from("ANMF")), "animated");
      const frames = bytes.toString("latin1").split("ANMF").length - 1;
      assert.equal(frames, 36);
      assert.match(await page.$eval("#turntableDownload", (a) => a.getAttribute("download")), /turntable-elbow_l\.webp/);
      await screenshot(page, "editor-3d-turntable.png");
      await closeDialogs();
      await page.evaluate(async () => { const m = await import("/js/store.js"); m.set({ selection: [] }); });
      assert.equal(await page.$eval("#turntable", (b) => b.disabled), true, "no selection: disabled");
    }],
    ["the compare menu says Compare and the 3D bar is one row in every mode at 1600 and 1280 px", async () => {
      await closeDialogs();
      for (const [w, h] of [[1600, 1000], [1280, 720]]) {
        await page.setViewportSize({ width: w, height: h });
        await page.click('[data-layout="both"]');
        for (const mode of ["off", "split", "flicker", "diff"]) {
          await page.selectOption("#compareMode", mode);
          if (mode !== "off") await page.selectOption("#compareAgainst", "off");
          await sleep(100);
          const bar = await page.$eval("#frameView .viewbar", (e) => {
            const r = e.getBoundingClientRect();
            // Every control shown in the row: inside the bar and clear of the others.
            const shown = [...e.querySelectorAll("select, button, input, .badge, .title")].filter((c) => {
              const b = c.getBoundingClientRect();
              return b.width > 0 && b.height > 0 && getComputedStyle(c).visibility !== "hidden" && b.top >= r.top - 1 && b.bottom <= r.bottom + 1;
            }).map((c) => ({ id: c.id || c.className || c.tagName, b: c.getBoundingClientRect() }));
            const clash = [];
            for (let i = 0; i < shown.length; ++i) {
              const a = shown[i].b;
              if (a.left < r.left - 1 || a.right > r.right + 1) clash.push(`${shown[i].id} outside`);
              for (let j = i + 1; j < shown.length; ++j) {
                const b = shown[j].b;
                if (a.left < b.right - 1 && b.left < a.right - 1 && a.top < b.bottom - 1 && b.top < a.bottom - 1) clash.push(`${shown[i].id} × ${shown[j].id}`);
              }
            }
            return { h: r.height, clash, n: shown.length };
          });
          assert.ok(bar.h < 40, `${w}px, ${mode}: one row (${bar.h} px)`);
          assert.deepEqual(bar.clash, [], `${w}px, ${mode}: every control whole and apart`);
          assert.ok(bar.n >= 5, `${w}px, ${mode}: the controls are there (${bar.n})`);
          if (mode !== "off") assert.ok(await page.isVisible("#compareAgainst"), `${w}px, ${mode}: "against" is shown`);
          if (mode === "diff") await until(() => page.isVisible("#diffText"), "the diff count is shown");
          const label = await page.$eval("#compareMode", (s) => { const l = s.closest("label").querySelector(".lbl"); return l && getComputedStyle(l).display !== "none" && l.getBoundingClientRect().width > 0 ? l.textContent : null; });
          assert.equal(label, "Compare", `${w}px, ${mode}: the compare menu's visible label`);
        }
        if (w === 1280) {
          await page.selectOption("#compareMode", "diff");
          await until(async () => /^\d+ px changed$/.test(await page.$eval("#diffText", (e) => e.textContent)), "the diff count");
          await screenshot(page, "editor-3d-diff-1280.png");
        }
        await page.selectOption("#compareMode", "off");
      }
    }],
    ["1280×720 with a highlighted, framed selection (screenshot)", async () => {
      await page.setViewportSize({ width: 1280, height: 720 });
      await page.click('[data-layout="both"]');
      await page.selectOption("#compareMode", "off");
      await page.evaluate(async () => { const m = await import("/js/store.js"); m.set({ selection: ["elbow_l"] }); });
      await page.focus("#frameStage");
      await page.keyboard.press("f");
      await until(async () => (await param("highlight")) === "elbow_l" && (await param("target")) !== null, "framed and highlighted");
      await settledFrameHash(page);
      await screenshot(page, "editor-3d-1280x720.png");
      await page.setViewportSize({ width: 1600, height: 1000 });
      await page.click('[data-layout="3d"]');
      await settledFrameHash(page);
      await screenshot(page, "editor-3d-1600x1000-elbow.png");
    }],
  ]);
  if (page.errors.length) { console.log("script errors:", page.errors); return failures + 1; }
  return failures;
}, async () => {
  await browser.close();
  server.stop();
});
