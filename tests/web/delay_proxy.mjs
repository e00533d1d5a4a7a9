// A slow link for the editor's latency tests: a userspace TCP proxy (node:net, no npm packages)
// that delays every chunk by a one-way delay and, optionally, serializes it at a bandwidth, in
// each direction. Both directions are one link each, shared by every connection (an access link):
// a chunk that arrives at time t leaves the sender's side when the link has finished the bytes
// before it — start = max(t, link free), free = start + bytes·8 / bandwidth — and is delivered
// `delayMs` after that (free + delay). Deliveries keep the order of arrival. A new connection
// costs one more round trip before its first bytes reach the target (the TCP handshake the
// proxy's own loopback accept hides): its first upstream bytes leave no earlier than
// accept + 2·delay.
//
// import { startDelayProxy } from "./delay_proxy.mjs";
//   const proxy = await startDelayProxy({ targetPort: 8080, delayMs: 50, mbit: 20 });
//   proxy.port, proxy.stats.up / .down (bytes client → target / target → client), .connections;
//   proxy.set({ delayMs, mbit }) changes the link for later chunks; await proxy.close().
//
// By hand (100 ms round trip, 20 Mbit/s each way, the editor on http://127.0.0.1:9000/):
//   node tests/web/delay_proxy.mjs --target 8080 --delay 50 --mbit 20 --port 9000
import net from "node:net";
import { pathToFileURL } from "node:url";

const SLICE = 16384;

/// Starts the proxy: listens on `port` (0: any free one) of `host` and forwards each connection to
/// `targetHost:targetPort`. `delayMs`: one-way delay; `mbit`: bandwidth of each direction in
/// Mbit/s (0: unlimited); `handshake`: charge a new connection its round trip (default true).
/// Resolves to { port, stats: { up, down, connections }, set({ delayMs, mbit }), close() }.
export async function startDelayProxy({ targetPort, targetHost = "127.0.0.1", port = 0, host = "127.0.0.1",
                                        delayMs = 0, mbit = 0, handshake = true } = {}) {
  if (!targetPort) throw new Error("startDelayProxy: targetPort is required");
  const cfg = { delayMs, mbit, handshake };
  const stats = { up: 0, down: 0, connections: 0 };
  const links = { up: { free: 0 }, down: { free: 0 } };
  const sockets = new Set();
  const pipes = new Set();

  /// When a chunk of `bytes` that may leave from `earliest` on is delivered.
  const schedule = (link, bytes, earliest) => {
    const serialize = cfg.mbit > 0 ? (bytes * 8) / (cfg.mbit * 1000) : 0; // ms
    const start = Math.max(earliest, link.free);
    link.free = start + serialize;
    return link.free + cfg.delayMs;
  };

  /// One direction of one connection: chunks from `from` to `to` over `link`, in order.
  function pipe(from, to, link, counter, notBefore) {
    const p = { queue: [], timer: null, last: 0, ended: false };
    pipes.add(p);
    const flush = () => {
      p.timer = null;
      const now = performance.now();
      while (p.queue.length && p.queue[0].at <= now + 0.5) {
        const item = p.queue.shift();
        if (item.end) { p.ended = true; if (to.writable) to.end(); pipes.delete(p); return; }
        if (to.writable) to.write(item.data);
      }
      if (p.queue.length) p.timer = setTimeout(flush, Math.max(0, p.queue[0].at - now));
    };
    const push = (item) => {
      p.queue.push(item);
      if (!p.timer && p.queue.length === 1) p.timer = setTimeout(flush, Math.max(0, item.at - performance.now()));
    };
    from.on("data", (data) => {
      stats[counter] += data.length;
      const now = performance.now();
      // In slices of ≤ 16 KB (a large read arrives as it is serialized, not all at its end), each
      // never before an earlier one of this connection (the delay may have changed since).
      for (let i = 0; i < data.length; i += SLICE) {
        const piece = data.subarray(i, i + SLICE);
        p.last = Math.max(p.last, schedule(link, piece.length, Math.max(now, notBefore)));
        push({ at: p.last, data: piece });
      }
    });
    from.on("end", () => push({ at: Math.max(p.last, performance.now() + cfg.delayMs), end: true }));
    p.cancel = () => { clearTimeout(p.timer); p.queue.length = 0; pipes.delete(p); };
    return p;
  }

  // Half-open sockets: an end (FIN) travels through the link like data, after the bytes before it.
  const server = net.createServer({ allowHalfOpen: true }, (client) => {
    ++stats.connections;
    const accepted = performance.now();
    const target = net.connect({ port: targetPort, host: targetHost, allowHalfOpen: true });
    client.setNoDelay(true);
    target.setNoDelay(true);
    sockets.add(client);
    sockets.add(target);
    const up = pipe(client, target, links.up, "up", cfg.handshake ? accepted + 2 * cfg.delayMs : 0);
    const down = pipe(target, client, links.down, "down", 0);
    const gone = () => { // a reset or a failed connect ends both sides at once
      up.cancel();
      down.cancel();
      client.destroy();
      target.destroy();
    };
    client.on("error", gone);
    target.on("error", gone);
    client.on("close", () => sockets.delete(client));
    target.on("close", () => sockets.delete(target));
  });
  await new Promise((resolve, reject) => {
    server.once("error", reject);
    server.listen(port, host, resolve);
  });
  return {
    port: server.address().port,
    stats,
    /// Changes the one-way delay and/or the bandwidth for chunks that arrive from now on.
    set({ delayMs: d, mbit: m } = {}) {
      if (d !== undefined) cfg.delayMs = d;
      if (m !== undefined) cfg.mbit = m;
    },
    /// Stops listening and drops every connection.
    close() {
      for (const p of pipes) p.cancel();
      for (const s of sockets) s.destroy();
      return new Promise((resolve) => server.close(() => resolve()));
    },
  };
}

// Standalone: node delay_proxy.mjs --target PORT [--target-host H] [--delay MS] [--mbit M] [--port P]
if (process.argv[1] && import.meta.url === pathToFileURL(process.argv[1]).href) {
  const args = process.argv.slice(2);
  const opt = (name, def) => { const i = args.indexOf(`--${name}`); return i >= 0 && i + 1 < args.length ? args[i + 1] : def; };
  if (args.includes("--help") || !opt("target")) {
    console.log("usage: node delay_proxy.mjs --target PORT [--target-host 127.0.0.1] [--delay MS one way] [--mbit MBIT/S each way, 0 unlimited] [--port PORT] [--host 127.0.0.1]");
    process.exit(args.includes("--help") ? 0 : 2);
  }
  const proxy = await startDelayProxy({ targetPort: +opt("target"), targetHost: opt("target-host", "127.0.0.1"),
                                        delayMs: +opt("delay", 0), mbit: +opt("mbit", 0), port: +opt("port", 0), host: opt("host", "127.0.0.1") });
  const host = opt("host", "127.0.0.1");
  console.log(`delay proxy: http://${host}:${proxy.port}/ -> ${opt("target-host", "127.0.0.1")}:${opt("target")}, ` +
              `${+opt("delay", 0)} ms each way (round trip ${2 * +opt("delay", 0)} ms), ${+opt("mbit", 0) || "unlimited"} Mbit/s each way`);
  setInterval(() => console.log(`  ${proxy.stats.connections} connections, ${(proxy.stats.down / 1e6).toFixed(2)} MB down, ${(proxy.stats.up / 1e6).toFixed(2)} MB up`), 10000).unref();
  const stop = async () => { await proxy.close(); process.exit(0); };
  process.on("SIGINT", stop);
  process.on("SIGTERM", stop);
}
