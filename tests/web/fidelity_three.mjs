// The peer renders of the fidelity comparison (issue #26): each glTF model drawn by three.js in
// headless Chromium (fidelity_three.html) under Dermis's studio environment, at Dermis's camera.
//   node fidelity_three.mjs ENV.raw OUT_DIR SIZE YAW PITCH MODEL.glb...
// ENV.raw: two uint32 (width, height) then width·height RGB float32, row 0 at the top (what
// PbrFidelityGLTest writes from core/environment's studioEnvironment). Writes OUT_DIR/three-<k>.png
// per model and prints one JSON line: [{model, distance, centre}] — the camera distance and
// target three.js used, which the test hands to Dermis so that both frames share the camera.
import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { readFileSync, writeFileSync, existsSync } from "node:fs";
import { dirname, join, extname } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const [envFile, outDir, sizeArg, yawArg, pitchArg, ...models] = process.argv.slice(2);
if (!envFile || !outDir || models.length === 0) {
    console.error("usage: node fidelity_three.mjs ENV.raw OUT_DIR SIZE YAW PITCH MODEL.glb...");
    process.exit(2);
}
const types = { ".html": "text/html", ".js": "text/javascript", ".glb": "model/gltf-binary" };
const server = createServer((req, res) => {
    const url = decodeURIComponent(req.url.split("?")[0]);
    let file = null;
    if (url === "/") file = join(here, "fidelity_three.html");
    else if (url === "/env") file = envFile;
    else if (url.startsWith("/model/")) file = models[Number(url.slice(7))];
    else if (url.startsWith("/three/") && !url.includes("..")) file = join(here, "node_modules", url.slice(1));
    if (!file || !existsSync(file)) {
        res.writeHead(404).end();
        return;
    }
    res.writeHead(200, { "Content-Type": types[extname(file)] || "application/octet-stream" });
    res.end(readFileSync(file));
});
await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
const out = [];
try {
    for (let k = 0; k < models.length; ++k) {
        const page = await browser.newPage();
        const errors = [];
        page.on("pageerror", (e) => errors.push(String(e)));
        page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
        await page.goto(base + "/");
        await page.waitForFunction(() => window.ready === true);
        const r = await page.evaluate((a) => window.renderModel(a), {
            model: `/model/${k}`, environment: "/env", size: Number(sizeArg), yaw: Number(yawArg), pitch: Number(pitchArg),
        });
        if (errors.length) console.error(`${models[k]}: ${errors.join("; ")}`);
        writeFileSync(join(outDir, `three-${k}.png`), Buffer.from(r.png.split(",")[1], "base64"));
        out.push({ model: models[k], distance: r.distance, centre: r.centre });
        await page.close();
    }
} finally {
    await browser.close();
    server.close();
}
console.log(JSON.stringify(out));
