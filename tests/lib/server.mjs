// Test helper for the Node suites (WebViewerBrowserTest, WebSessionBrowserTest, OpenApiHttpTest):
// starts a real dermis-server on 127.0.0.1 (any free port) with a fresh data folder, on the GL
// backend $DERMIS_TEST_GL, and waits for its "serving http://127.0.0.1:<port>/" line. No npm
// dependencies. Rejects (with the server's output) when it exits or does not start within 60 s.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

/// { port, base ("http://127.0.0.1:<port>"), stop() } for `exe serve … extraArgs`.
export async function startServer(exe, extraArgs = [], prefix = "dermis-test-") {
  const data = mkdtempSync(join(tmpdir(), prefix));
  const server = spawn(exe, ["serve", "--port", "0", "--data", data,
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
  return {
    port,
    base: `http://127.0.0.1:${port}`,
    stop() {
      server.kill("SIGTERM");
      rmSync(data, { recursive: true, force: true });
    },
  };
}
