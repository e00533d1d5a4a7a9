// OpenApiHttpTest — the API's schemas hold against what the server really answers. Validates
// with ajv (a well-kept JSON Schema validator from npm) against a real dermis-server on 127.0.0.1:
//   * the dermis.scene/1 JSON Schema (served at /api/v1/schemas/scene.json) compiles, accepts every
//     documented example (models/default.scene.json, examples/*.scene.json, the SPEC's example in
//     the schema's own tests below) and refuses broken documents;
//   * every response schema in openapi.yaml compiles, and live answers of the routes that have one
//     (scenes, history, presence, pick, probe, activation, lint, sweep steps, errors) validate
//     against it;
//   * a wrong answer (a scene answer without its revision, a placement with h < 0, an error
//     without its code) fails — so the schemas are not vacuous.
// Usage: node validate.test.mjs <dermis-server> <source dir>   (exit 0 = pass)
import Ajv from "ajv";
import addFormats from "ajv-formats";
import yaml from "js-yaml";
import { readFileSync, readdirSync } from "node:fs";
import { join } from "node:path";
import assert from "node:assert/strict";
import { startServer } from "../lib/server.mjs";

const [exe, source] = process.argv.slice(2);
const server = await startServer(exe, [], "dermis-openapi-");
const base = `${server.base}/api/v1`;
const call = async (method, path, body) => {
  const r = await fetch(base + path, {
    method, headers: body ? { "Content-Type": "application/json" } : {},
    body: body ? JSON.stringify(body) : undefined,
  });
  const text = await r.text();
  return { status: r.status, type: r.headers.get("content-type") || "", text,
           json: () => JSON.parse(text) };
};

let failed = false;
try {
  const ajv = new Ajv({ strict: false, allErrors: true });
  addFormats(ajv);

  // --- the scene schema, served and in the tree, identical
  const served = await call("GET", "/schemas/scene.json");
  assert.equal(served.status, 200);
  assert.match(served.type, /application\/schema\+json/);
  const sceneSchema = served.json();
  assert.deepEqual(sceneSchema, JSON.parse(readFileSync(join(source, "server/http/schemas/scene.json"), "utf8")));
  const validScene = ajv.compile(sceneSchema);
  const examples = [join(source, "models/default.scene.json"),
    ...readdirSync(join(source, "examples")).filter((f) => f.endsWith(".scene.json")).map((f) => join(source, "examples", f))];
  for (const file of examples) {
    const doc = JSON.parse(readFileSync(file, "utf8"));
    assert.ok(validScene(doc), `${file}: ${ajv.errorsText(validScene.errors)}`);
  }
  const spec = {
    format: "dermis.scene/1", model: "builtin:default",
    heightmap: { size: [1024, 1024], base: "optional/static_height.exr" },
    patterns: { my_ridge: "custom/ridge.png" },
    placements: [{ id: "elbow_l", pattern: "crease", center: [0.31, 0.42], scale: [0.08, 0.05], rotation: 30,
                   joint: "forearm.l", axis: "x", theta_min: 0, theta_max: 120, h: 1.0, model: "scale",
                   target: "bump", response: "log2" }],
    pose: { animation: "Walk", time: 0.5, joints: { "forearm.l": { rotation: [0, 0, 0.383, 0.924] },
                                                     spine: { axis_angles: { x: 20, y: -10 } } } },
    render: { size: [1024, 1024], camera: { yaw: 0, pitch: 10, distance: "auto" },
              displacement_scale: "auto", bump_strength: 1.0 },
  };
  assert.ok(validScene(spec), "the SPEC's example: " + ajv.errorsText(validScene.errors));
  const broken = [
    { ...spec, format: "dermis.scene/2" },
    { ...spec, placements: [{ ...spec.placements[0], h: -1 }] },
    { ...spec, placements: [{ ...spec.placements[0], axis: "w" }] },
    { ...spec, placements: [{ ...spec.placements[0], label: "x".repeat(121) }] },
    { ...spec, render: { ...spec.render, msaa: 3 } },
    { ...spec, pose: { joints: { a: { rotation: [0, 0, 0, 1], axis_angles: { x: 1 } } } } },
  ];
  for (const doc of broken) assert.ok(!validScene(doc), "a broken document passed: " + JSON.stringify(doc).slice(0, 120));

  // --- every OpenAPI response schema compiles (with the scene schema known by its $id)
  const openapi = yaml.load((await call("GET", "/openapi.yaml")).text);
  // (the scene schema is known by its $id since it was compiled above)
  ajv.addSchema({ $id: "openapi", components: openapi.components }, "openapi");
  const fixRefs = (s) => JSON.parse(JSON.stringify(s).replaceAll('"#/components/', '"openapi#/components/'));
  const validators = new Map();
  for (const [path, ops] of Object.entries(openapi.paths))
    for (const [method, op] of Object.entries(ops))
      for (const [status, r] of Object.entries(op.responses || {})) {
        const resp = r.$ref ? openapi.components.responses[r.$ref.split("/").pop()] : r;
        const schema = resp?.content?.["application/json"]?.schema;
        if (!schema || Object.keys(schema).length === 0) continue;
        validators.set(`${method.toUpperCase()} ${path} ${status}`, ajv.compile(fixRefs(schema)));
      }
  assert.ok(validators.size >= 12, `only ${validators.size} response schemas`);
  const check = (key, status, body) => {
    const v = validators.get(`${key} ${status}`) || validators.get(`${key} default`);
    assert.ok(v, `no schema for ${key} ${status}`);
    assert.ok(v(body), `${key} ${status}: ${ajv.errorsText(v.errors)}\n${JSON.stringify(body).slice(0, 300)}`);
    return v;
  };

  // --- live answers
  const created = await call("POST", "/scenes", { default_patterns: true });
  assert.equal(created.status, 201);
  const createdBody = created.json();
  const sceneValidator = check("POST /scenes", 201, createdBody);
  const id = createdBody.id;
  const s = `/scenes/${id}`;
  check("GET /scenes/{id}", 200, (await call("GET", s)).json());
  await call("PATCH", s + "/placements/elbow_l", { h: 1.5, label: "left elbow" });
  check("GET /scenes/{id}", 200, (await call("GET", s + "?revision=1")).json());
  check("GET /scenes/{id}/revisions", 200, (await call("GET", s + "/revisions")).json());
  check("POST /scenes/{id}/presence", 200, (await call("POST", s + "/presence", { client: "ana", selection: ["elbow_l"], color: "#f80" })).json());
  check("GET /scenes/{id}/presence", 200, (await call("GET", s + "/presence")).json());
  check("GET /scenes/{id}/probe", 200, (await call("GET", s + "/probe?u=0.29&v=0.737")).json());
  check("GET /scenes/{id}/activation", 200, (await call("GET", s + "/activation?clip=squat&fps=10")).json());
  check("GET /scenes/{id}/lint", 200, (await call("GET", s + "/lint")).json());
  check("GET /scenes/{id}/sweep", 200, (await call("GET", s + "/sweep?placement=clavicle_r&steps=4&format=json")).json());
  check("GET /scenes/{id}/sweep", 200, (await call("GET", s + "/sweep?clip=squat&steps=4&format=json")).json());
  check("GET /scenes/{id}/sweep", 200, (await call("GET", s + "/sweep?clip=squat&placement=knee_l&steps=4&format=json")).json());
  check("GET /scenes/{id}/pick", 200, (await call("GET", s + "/pick?x=128&y=100&width=256&height=256")).json());
  check("GET /scenes/{id}/pick", 200, (await call("GET", s + "/pick?x=1&y=1&width=256&height=256")).json());
  const notFound = await call("GET", "/scenes/s_0000000000000000");
  assert.equal(notFound.status, 404);
  const errorValidator = check("GET /scenes/{id}", 404, notFound.json());
  const stale = await fetch(base + s + "/pose", { method: "PATCH", headers: { "Content-Type": "application/json", "If-Match": '"r1"' }, body: "{}" });
  assert.equal(stale.status, 412);
  const staleBody = await stale.json();
  check("PATCH /scenes/{id}/pose", 412, staleBody);
  assert.equal(staleBody.revision, 2);

  // --- the schemas fail on wrong answers
  const noRevision = { ...createdBody };
  delete noRevision.revision;
  assert.ok(!sceneValidator(noRevision), "a scene answer without its revision passed");
  const badPlacement = structuredClone(createdBody);
  badPlacement.scene.placements[0].h = -1;
  assert.ok(!sceneValidator(badPlacement), "a scene answer with h < 0 passed");
  assert.ok(!errorValidator({ error: { message: "no code" } }), "an error without its code passed");
  console.log(`OpenApiHttpTest: ${examples.length + 1} documented scenes, ${validators.size} response schemas, live answers valid`);
} catch (e) {
  failed = true;
  console.error(e);
} finally {
  server.stop();
}
process.exit(failed ? 1 : 0);
