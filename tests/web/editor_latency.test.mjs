// WebEditorLatencyBrowserTest — remote authoring (issue #28, docs/remote-authoring.md): the editor
// in Debian's Chromium (playwright-core) against a real dermis-server on 127.0.0.1, first directly
// (loopback), then opened THROUGH a slow link (delay_proxy.mjs: a one-way delay and 20 Mbit/s each
// way) at 0, 50 and 100 ms round trip, dragging the `stomach` footprint in the texture view for
// 2.5 s (a pointer move every 16–33 ms, as a person's drag). On each link, after a short warm-up
// drag, two drags: the editor as it is (frames pipelined while a gesture runs: "after") and capped
// at one frame request in flight (frameStats.inFlightLimit = 1: the editor before, "before").
// Usage: node editor_latency.test.mjs <dermis-server executable>   (exit 0 = pass)
// Optional: LAT_RTTS=0,100 (the round trips), LAT_MBIT=20, LAT_DEBUG=1 (each drag's trace as JSON).
//
// Measures per drag: frames shown during the drag, frames per second, frame age p50/p95 (on
// screen − when the editor wanted that frame's state), bytes down/up through the proxy during the
// drag, the most requests in flight, the editor's estimates (server ms per frame, the rest of a
// round trip, k) and pointerup → the final lossless frame on screen. Prints one JSON line
// {"benchmark":"editor_remote_drag", "runs":[…]} and writes it to
// $DERMIS_TEST_OUT/editor-latency-bench.json. Speed is reported, never asserted.
// Checks: after every drag the editor ends on the exact final frame (its URL is the state's frame
// URL, lossless, no preview; the bytes on screen equal a direct request of that URL, not through
// the proxy) and frames went on screen in the order they were wanted (never an older one over a
// newer one); at 100 ms RTT the frame stream continues during the drag (frames in ≥ 3 of the 5
// half-second windows) with more than one request in flight (at most 4), and with the cap at one
// never more. Against the editor before pipelining the 100 ms check fails (one request in flight).
import assert from "node:assert/strict";
import { writeFileSync } from "node:fs";
import { createHash } from "node:crypto";
import { join } from "node:path";
import { startServer, launch, apiClient, openEditor, footprint, screenshot, runChecks, runSuite, settled, shotDir } from "./editor_lib.mjs";
import { startDelayProxy } from "./delay_proxy.mjs";

const RTTS = process.env.LAT_RTTS ? process.env.LAT_RTTS.split(",").map(Number) : [0, 50, 100]; // ms; the proxy delays each way by half
const MBIT = process.env.LAT_MBIT ? +process.env.LAT_MBIT : 20;
const DRAG_MS = 2500;
const WINDOWS = 5;

const server = await startServer(process.argv[2], [], "dermis-editor-latency-");
const api = apiClient(server.base);
const browser = await launch();
const proxies = [];
const sha = (bytes) => createHash("sha256").update(bytes).digest("hex");
const quantile = (xs, q) => { const v = [...xs].sort((a, b) => a - b); return v.length ? +v[Math.min(v.length - 1, Math.floor(q * v.length))].toFixed(1) : null; };

/// One drag of `stomach` on `page` (the editor through `proxy`) with `limit` requests in flight at
/// most (null: the editor's own pipelining). Returns the run's figures and its trace.
let drags = 0;
/// The stomach placement's centre on the server (the scene `page` shows).
const stomachCentre = async (page) => {
  const id = await page.evaluate(() => window.dermisEditor.store.sceneId);
  return (await api("GET", `/scenes/${id}`)).body.scene.placements.find((p) => p.id === "stomach").center;
};

async function drag(page, proxy, rtt, limit, direct = false, ms = DRAG_MS) {
  await settled(page, api);
  const g = await footprint(page, "stomach");
  assert.ok(g, "the stomach footprint is in the texture view");
  const centre0 = await stomachCentre(page);
  const dir = drags++ % 2 ? -1 : 1; // drags end 10 px right and left in turn: the footprint stays put
  const counts0 = await page.evaluate((lim) => {
    const d = window.dermisEditor;
    d.frameStats.inFlightLimit = lim;
    d.frameStats.peakInFlight = 0;
    d.clearTrace();
    d.trace.on = true;
    return { requested: d.frameStats.requested, dropped: d.frameStats.dropped };
  }, limit);
  const before = { ...proxy.stats };
  // The drag: pointer down on the footprint's centre, a move every 16–33 ms along a wobbling
  // path (each move a new position: a new frame wanted), the last move and the pointer up 10 px
  // right of where it started (left on every second drag: the footprint does not wander off).
  const times = await page.evaluate(([x0, y0, ms, dir]) => new Promise((resolve) => {
    const c = document.getElementById("uv");
    const ev = (type, x, y) => c.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, button: 0, buttons: type === "pointerup" ? 0 : 1, pointerId: 7, bubbles: true }));
    const downAt = performance.now();
    ev("pointerdown", x0, y0);
    let i = 0;
    const step = () => {
      const t = performance.now() - downAt;
      if (t >= ms) { // the last move and the pointer up exactly at the path's end
        ev("pointermove", x0 + dir * 10, y0 + dir * 5);
        ev("pointerup", x0 + dir * 10, y0 + dir * 5);
        resolve({ downAt, upAt: performance.now(), moves: i + 1 });
        return;
      }
      ++i;
      const f = t / ms;
      ev("pointermove", x0 + 22 * Math.sin(2 * Math.PI * 2 * f) + dir * 10 * f, y0 + 12 * Math.sin(2 * Math.PI * 3 * f) + dir * 5 * f);
      setTimeout(step, 16 + ((i * 7) % 18)); // 16–33 ms apart
    };
    setTimeout(step, 16);
  }), [g.center[0], g.center[1], ms, dir]);
  const during = direct ? { down: null, up: null, connections: null }
                        : { down: proxy.stats.down - before.down, up: proxy.stats.up - before.up, connections: proxy.stats.connections - before.connections };
  await settled(page, api);
  assert.notDeepEqual(await stomachCentre(page), centre0, "the drag moved the stomach footprint");
  // The final frame: the state's URL, lossless and no preview, its bytes on screen equal to a
  // direct request (not through the proxy).
  await page.waitForFunction(() => {
    const i = document.getElementById("frame");
    return i.complete && i.naturalWidth > 0 && i.dataset.url === window.dermisEditor.frameUrl();
  }, null, { timeout: 30000 });
  const shown = await page.evaluate(async () => {
    const i = document.getElementById("frame");
    const b = await (await fetch(i.src)).arrayBuffer();
    const d = window.dermisEditor;
    return { url: i.dataset.url, bytes: Array.from(new Uint8Array(b)), peak: d.frameStats.peakInFlight, pipeline: d.frameStats.pipeline,
             requested: d.frameStats.requested, dropped: d.frameStats.dropped,
             trace: JSON.parse(JSON.stringify(d.trace)), gestures: d.store.gestures };
  });
  await page.evaluate(() => { window.dermisEditor.trace.on = false; window.dermisEditor.frameStats.inFlightLimit = null; });
  const tr = shown.trace;
  const frames = tr.frames.filter((f) => f.shownAt > times.downAt && f.shownAt <= times.upAt);
  const windows = Array.from({ length: WINDOWS }, (_, w) => frames.filter((f) => f.shownAt - times.downAt > w * DRAG_MS / WINDOWS && f.shownAt - times.downAt <= (w + 1) * DRAG_MS / WINDOWS).length);
  const ages = frames.map((f) => f.shownAt - f.t0);
  const last = tr.frames[tr.frames.length - 1];
  const run = {
    link: direct ? "loopback" : "proxy", rtt_ms: rtt, mbit: direct ? null : MBIT, mode: limit === 1 ? "before: 1 in flight" : "after: pipelined",
    frames_shown: frames.length, frames_per_s: +(frames.length / ((times.upAt - times.downAt) / 1000)).toFixed(1),
    age_p50_ms: quantile(ages, 0.5), age_p95_ms: quantile(ages, 0.95),
    bytes_down: during.down, bytes_up: during.up, connections_opened: during.connections, moves: times.moves, windows,
    requested: shown.requested - counts0.requested, dropped: shown.dropped - counts0.dropped,
    peak_in_flight: shown.peak, k: shown.pipeline ? shown.pipeline.k : null,
    server_ms: shown.pipeline ? shown.pipeline.serverMs : null, net_ms: shown.pipeline ? shown.pipeline.rttMs : null,
    server_dur_p50_ms: quantile(frames.map((f) => f.dur).filter((x) => x !== null && x !== undefined), 0.5),
    final_frame_ms: last ? +(last.shownAt - times.upAt).toFixed(1) : null,
    preview_side_p50: quantile(frames.map((f) => f.side), 0.5),
  };
  if (process.env.LAT_DEBUG) writeFileSync(join(shotDir, `lat-trace-${direct ? "direct" : rtt}-${limit || "k"}.json`), JSON.stringify({ times, tr }, null, 1));
  return { run, shown, tr };
}

/// The bytes of `url` (under /api/v1) asked of the server directly.
async function directBytes(url) {
  const r = await fetch(server.base + "/api/v1" + url);
  assert.equal(r.status, 200, `direct GET ${url}`);
  return Buffer.from(await r.arrayBuffer());
}

/// The checks every drag must pass: the exact final frame, frames in order.
async function checkDrag({ run, shown, tr }) {
  const what = `${run.link === "loopback" ? "loopback" : `${run.rtt_ms} ms RTT`}, ${run.mode}`;
  assert.equal(shown.gestures, 0, `${what}: the gesture ended`);
  assert.ok(!/[?&]preview=/.test(shown.url) && !/[?&]format=jpeg/.test(shown.url), `${what}: the final frame is lossless and no preview: ${shown.url.slice(0, 200)}`);
  assert.equal(sha(Buffer.from(shown.bytes)), sha(await directBytes(shown.url)), `${what}: the bytes on screen are the final frame's`);
  const seqs = tr.frames.map((f) => f.seq);
  for (let i = 1; i < seqs.length; ++i) assert.ok(seqs[i] > seqs[i - 1], `${what}: frame ${seqs[i]} went on screen after ${seqs[i - 1]}`);
  assert.ok(run.frames_shown > 0, `${what}: frames during the drag`);
  assert.ok(/[?&]width=512(&|$)/.test(shown.url), `${what}: the final frame is full size: ${shown.url.slice(0, 200)}`);
}

await runSuite("WebEditorLatencyBrowserTest", async () => {
  const runs = [];
  let slow = null; // the 100 ms drags, for the stream checks
  // First the editor on the server directly (loopback: no proxy, no bandwidth limit), then
  // through the proxy at each round trip.
  const links = [{ rtt: 0, direct: true }, ...RTTS.map((rtt) => ({ rtt }))];
  const checks = links.map(({ rtt, direct }) => [`${direct ? "loopback (no proxy)" : `${rtt} ms round trip, ${MBIT} Mbit/s`}: two drags end on the exact final frame, frames in order`, async () => {
    const proxy = await startDelayProxy({ targetPort: server.port, delayMs: rtt / 2, mbit: MBIT });
    proxies.push(proxy);
    const context = await browser.newContext();
    try {
      const page = await openEditor(context, direct ? server.base + "/" : `http://127.0.0.1:${proxy.port}/`);
      await page.evaluate(() => window.dermisEditor.select(["stomach"]));
      await drag(page, proxy, rtt, null, direct, 600); // a warm-up: the first drag of a page is slower
      const after = await drag(page, proxy, rtt, null, direct);
      const before = await drag(page, proxy, rtt, 1, direct);
      runs.push(after.run, before.run);
      console.log(`  ${JSON.stringify(after.run)}\n  ${JSON.stringify(before.run)}`);
      if (rtt === 100) { slow = { after, before }; await screenshot(page, "editor-latency-100ms.png"); }
      await checkDrag(after);
      await checkDrag(before);
      assert.deepEqual(page.errors, [], "no script errors");
    } finally {
      await context.close();
      await proxy.close();
    }
  }]);
  checks.push(["at 100 ms RTT the frame stream continues during the drag, more than one request in flight", async () => {
    assert.ok(slow, "the 100 ms drags ran");
    const { after, before } = slow;
    const busy = after.run.windows.filter((n) => n > 0).length;
    assert.ok(busy >= 3, `frames in ${busy} of ${WINDOWS} half-second windows: ${after.run.windows}`);
    assert.ok(after.run.peak_in_flight > 1, `at most ${after.run.peak_in_flight} frame request(s) in flight`);
    assert.ok(after.run.peak_in_flight <= 4, `${after.run.peak_in_flight} frame requests in flight (≤ 4: the event stream and an edit keep their connections)`);
    assert.equal(before.run.peak_in_flight, 1, "capped at one, one in flight");
    // Over the slow link the drag's previews are half size (frame_view.js shownParams).
    assert.equal(after.run.preview_side_p50, 256, `the previews during the 100 ms drag are 256² (median side ${after.run.preview_side_p50})`);
  }]);
  const failures = await runChecks("WebEditorLatencyBrowserTest", checks);
  const figures = { benchmark: "editor_remote_drag", frame: "512x512", drag_ms: DRAG_MS, gl: process.env.DERMIS_TEST_GL || "auto", runs };
  console.log(JSON.stringify(figures));
  writeFileSync(join(shotDir, "editor-latency-bench.json"), JSON.stringify(figures, null, 2) + "\n");
  return failures;
}, async () => {
  for (const p of proxies) await p.close().catch(() => {});
  await browser.close();
  server.stop();
});
