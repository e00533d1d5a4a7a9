// Test helper for the Node suites (Web*BrowserTest, OpenApiHttpTest): starts a real dermis-server
// on 127.0.0.1 (any free port, or `port`) with a fresh data folder (or `data`), on the GL backend
// $DERMIS_TEST_GL, and waits for its "serving http://127.0.0.1:<port>/" line. No npm
// dependencies. Rejects (with the server's output) when it exits or does not start within 60 s.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

/// { port, base ("http://127.0.0.1:<port>"), data, kill() (keeps the data), stop() } for
/// `exe serve … extraArgs`; options: { port, data } to restart a server where one ran.
export async function startServer(exe, extraArgs = [], prefix = "dermis-test-", options = {}) {
  const data = options.data || mkdtempSync(join(tmpdir(), prefix));
  const server = spawn(exe, ["serve", "--port", String(options.port || 0), "--data", data,
                             "--gl", process.env.DERMIS_TEST_GL || "auto", ...extraArgs]);
  let output = "";
  const port = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error("server did not start: " + output)), 60000);
    server.stdout.on("data", (d) => {
      output += d;
      const m = output.match(/serving http:\/\/127\.0\.0\.1:(\d+)\//);
      if (m) { clearTimeout(timer); resolve(+m[1]); }
    });
    server.stderr.on("data", (d) => { output += d; });
    server.on("exit", (code) => reject(new Error(`server exited ${code}: ${output}`)));
  });
  const exited = new Promise((resolve) => server.on("exit", resolve));
  return {
    port,
    data,
    base: `http://127.0.0.1:${port}`,
    /// Stops the server and waits for it; the data folder stays (for a restart).
    async kill() {
      server.kill("SIGTERM");
      await exited;
    },
    stop() {
      server.kill("SIGTERM");
      rmSync(data, { recursive: true, force: true });
    },
  };
}
