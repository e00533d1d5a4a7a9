// OpenApiHttpTest — the API's schemas hold against what the server really answers. Validates
// with ajv (a well-kept JSON Schema validator from npm) against a real dermis-server on 127.0.0.1:
//   * the dermis.scene/1 JSON Schema (served at /api/v1/schemas/scene.json) compiles, accepts every
//     documented example (models/default.scene.json, examples/*.scene.json, the SPEC's example in
//     the schema's own tests below) and refuses broken documents;
//   * openapi.yaml: no request or response content has an empty schema (`schema: {}`), every JSON
//     request and answer schema compiles and has an example, and every documented example (request
//     bodies, answers, shared error answers, component schemas, the event stream's) validates;
//   * every operation of openapi.yaml is called live (the test fails on one it did not call): each
//     JSON body the test sends validates against the operation's request schema; each answer's
//     status is documented (2xx explicitly), its Content-Type is one the status documents, and a
//     JSON answer validates against that status's schema — success and error answers (400, 404,
//     409, 412, 415, 422) alike; server-sent events validate against components/schemas/Event; the
//     batch's multipart/mixed parts are counted and checked;
//   * wrong answers and wrong requests fail (a model summary with a string triangle count, a
//     placement with an unknown field, an error without its code, …) — the schemas are not vacuous.
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
const mediaType = (ct) => (ct || "").split(";")[0].trim().toLowerCase();
const isJsonMedia = (m) => m === "application/json";

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

  // --- the OpenAPI document: every schema present, compiled, every example valid
  const openapiText = (await call("GET", "/openapi.yaml")).text;
  assert.equal(openapiText, readFileSync(join(source, "server/http/openapi.yaml"), "utf8"));
  const openapi = yaml.load(openapiText);
  // (the scene schema is known by its $id since it was compiled above)
  const fixRefs = (s) => JSON.parse(JSON.stringify(s).replaceAll('"#/components/', '"openapi#/components/'));
  ajv.addSchema(fixRefs({ $id: "openapi", components: openapi.components }));
  const component = (ref, kind) => {
    assert.ok(ref.startsWith(`#/components/${kind}/`), `unexpected $ref ${ref}`);
    const c = openapi.components[kind][ref.split("/").pop()];
    assert.ok(c, `dangling $ref ${ref}`);
    return c;
  };
  const compiled = new Map(); // schema JSON → validator (schemas shared by $ref compile once)
  const compile = (schema) => {
    const key = JSON.stringify(schema);
    if (!compiled.has(key)) compiled.set(key, ajv.compile(fixRefs(schema)));
    return compiled.get(key);
  };
  const componentSchema = (name) => compile({ $ref: `#/components/schemas/${name}` });

  const documentedExamples = new Set(); // each example once, however many operations share it
  const validateExample = (where, v, value) => {
    assert.ok(v(value), `${where}: documented example is invalid: ${ajv.errorsText(v.errors)}\n${JSON.stringify(value).slice(0, 300)}`);
    documentedExamples.add(JSON.stringify(value));
  };
  const eventValidator = componentSchema("Event");
  const sseEvents = (text) => text.split("\n\n").filter((b) => b.trim() && !b.startsWith(":")).map((block) => {
    const name = /^event: (.*)$/m.exec(block)?.[1];
    const data = /^data: (.*)$/m.exec(block)?.[1];
    assert.ok(name && data, `not a server-sent event: ${block}`);
    return { name, data: JSON.parse(data) };
  });
  const checkEvent = (where, e) => {
    assert.ok(eventValidator(e.data), `${where}: event ${JSON.stringify(e.data)}: ${ajv.errorsText(eventValidator.errors)}`);
    const expectedName = { hello: "hello", presence: "presence", resync: "resync" }[e.data.type] || "change";
    assert.equal(e.name, expectedName, `${where}: event ${e.data.type} named ${e.name}`);
  };

  /// Checks one content map (request body or answer): no empty schema; a JSON one compiles and has
  /// an example (its own or its schema component's); every example validates.
  const checkContent = (where, content) => {
    const out = new Map();
    for (const [media, m] of Object.entries(content || {})) {
      const here = `${where} ${media}`;
      assert.ok(m.schema && Object.keys(m.schema).length > 0, `${here}: empty schema (schema: {})`);
      if (media === "text/event-stream" && m.example !== undefined) {
        for (const e of sseEvents(m.example)) checkEvent(here, e);
        documentedExamples.add(m.example);
      }
      if (!isJsonMedia(media)) continue;
      const v = compile(m.schema);
      out.set(media, v);
      const examples = [];
      if (m.example !== undefined) examples.push(m.example);
      for (const e of Object.values(m.examples || {})) examples.push(e.value);
      const componentExample = m.schema.$ref && component(m.schema.$ref, "schemas").example;
      assert.ok(examples.length > 0 || componentExample !== undefined, `${here}: no example`);
      for (const e of examples) validateExample(here, v, e);
    }
    return out;
  };
  for (const [name, r] of Object.entries(openapi.components.responses)) checkContent(`components/responses/${name}`, r.content);
  for (const [name, s] of Object.entries(openapi.components.schemas))
    if (s.example !== undefined) validateExample(`components/schemas/${name}`, componentSchema(name), s.example);

  const operations = new Map(); // "METHOD /template" → { request: Map, responses: {status: {content, validators}} }
  for (const [path, ops] of Object.entries(openapi.paths))
    for (const [method, op] of Object.entries(ops)) {
      const key = `${method.toUpperCase()} ${path}`;
      const entry = { request: new Map(), responses: {} };
      if (op.requestBody) entry.request = checkContent(`${key} request`, op.requestBody.content);
      assert.ok(op.responses && Object.keys(op.responses).some((s) => /^2/.test(s)), `${key}: no success answer`);
      for (const [status, r] of Object.entries(op.responses)) {
        const resp = r.$ref ? component(r.$ref, "responses") : r;
        if (!/^2/.test(status)) // every error answer is the shared envelope
          assert.equal(resp.content?.["application/json"]?.schema?.$ref, "#/components/schemas/Error", `${key} ${status}: not the Error envelope`);
        entry.responses[status] = { content: resp.content || {}, validators: checkContent(`${key} ${status}`, resp.content) };
      }
      operations.set(key, entry);
    }
  assert.ok(operations.size >= 40, `only ${operations.size} operations`);

  // --- live calls: every request body and every answer checked against the document
  const called = new Set();
  const fill = (template, params) => template.replace(/\{(\w+)\}/g, (_, k) => {
    assert.ok(params[k] !== undefined, `${template}: no value for {${k}}`);
    return encodeURIComponent(params[k]);
  });
  /// Calls `METHOD template` (path parameters from `params`, `query` appended). `body`: a JSON
  /// value (validated against the request schema unless `invalidRequest`), or { raw, type } to
  /// send bytes. Returns { status, media, headers, bytes, text, json }.
  const api = async (method, template, { params = {}, query = "", body, headers = {}, invalidRequest = false, expect } = {}) => {
    const key = `${method} ${template}`;
    const op = operations.get(key);
    assert.ok(op, `${key} is not in openapi.yaml`);
    let payload;
    const h = { ...headers };
    if (body !== undefined && body !== null && body.raw !== undefined) {
      payload = body.raw;
      if (body.type) h["Content-Type"] = body.type;
    } else if (body !== undefined) {
      const v = op.request.get("application/json");
      assert.ok(v, `${key}: no JSON request schema`);
      const ok = v(body);
      if (!invalidRequest) assert.ok(ok, `${key} request: ${ajv.errorsText(v.errors)}\n${JSON.stringify(body).slice(0, 300)}`);
      else assert.ok(!ok, `${key}: a wrong request body passed its schema: ${JSON.stringify(body).slice(0, 200)}`);
      payload = JSON.stringify(body);
      h["Content-Type"] = "application/json";
    }
    const r = await fetch(base + fill(template, params) + (query ? "?" + query : ""), { method, headers: h, body: payload });
    const bytes = Buffer.from(await r.arrayBuffer());
    const answer = { status: r.status, media: mediaType(r.headers.get("content-type")), headers: r.headers, bytes,
                     text: bytes.toString("utf8") };
    answer.json = () => JSON.parse(answer.text);
    const where = `${key} → ${r.status}`;
    if (expect !== undefined) assert.equal(r.status, expect, `${where}: expected ${expect}: ${answer.text.slice(0, 300)}`);
    const documented = op.responses[String(r.status)] || (r.status >= 400 ? op.responses.default : undefined);
    assert.ok(documented, `${where}: status not documented`);
    const medias = Object.keys(documented.content);
    if (medias.length === 0) assert.equal(bytes.length, 0, `${where}: a body where none is documented`);
    else assert.ok(medias.some((m) => m === answer.media || (m.endsWith("/*") && answer.media.startsWith(m.slice(0, -1)))),
                   `${where}: Content-Type ${answer.media} not among ${medias}`);
    const v = documented.validators.get(answer.media);
    if (v) assert.ok(v(answer.json()), `${where}: ${ajv.errorsText(v.errors)}\n${answer.text.slice(0, 300)}`);
    called.add(key);
    return answer;
  };
  const isPng = (b) => b.subarray(0, 4).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47]));
  const isJpeg = (b) => b[0] === 0xff && b[1] === 0xd8;

  // system, session
  await api("GET", "/health", { expect: 200 });
  await api("GET", "/info", { expect: 200 });
  await api("GET", "/openapi.yaml", { expect: 200 });
  await api("GET", "/schemas/scene.json", { expect: 200 });
  await api("POST", "/session", { body: { token: "anything" }, expect: 204 }); // no token configured
  await api("POST", "/session", { body: { token: 42 }, invalidRequest: true, expect: 422 });
  await api("DELETE", "/session", { expect: 204 });

  // models: a .glb, a .gltf with its buffer as multipart parts, details, UV layout, delete
  const glb = readFileSync(join(source, "tests/models/RiggedFigure/RiggedFigure.glb"));
  const uploaded = (await api("POST", "/models", { query: "name=RiggedFigure", body: { raw: glb, type: "model/gltf-binary" }, expect: 201 })).json();
  // Content-addressed (issue #14): the same bytes again answer 200 with the same id.
  const again = (await api("POST", "/models", { query: "name=copy", body: { raw: glb, type: "model/gltf-binary" }, expect: 200 })).json();
  assert.equal(again.id, uploaded.id);
  await api("POST", "/models", { body: { raw: "not a model", type: "text/plain" }, expect: 415 });
  const jsonLength = glb.readUInt32LE(12);
  const gltf = JSON.parse(glb.subarray(20, 20 + jsonLength).toString("utf8"));
  const bin = glb.subarray(20 + jsonLength + 8, 20 + jsonLength + 8 + glb.readUInt32LE(20 + jsonLength));
  gltf.buffers[0].uri = "figure.bin";
  const form = new FormData();
  form.append("gltf", new Blob([JSON.stringify(gltf)], { type: "model/gltf+json" }), "figure.gltf");
  form.append("figure.bin", new Blob([bin], { type: "application/octet-stream" }), "figure.bin");
  const uploadedGltf = (await api("POST", "/models", { body: { raw: form }, expect: 201 })).json();
  assert.equal(uploadedGltf.triangles, uploaded.triangles);
  await api("GET", "/models", { expect: 200 });
  await api("GET", "/models/{id}", { params: { id: uploaded.id }, expect: 200 });
  await api("GET", "/models/{id}", { params: { id: "builtin:default" }, expect: 200 });
  await api("GET", "/models/{id}", { params: { id: "m_0000000000000000" }, expect: 404 });
  const uv = await api("GET", "/models/{id}/uv-layout", { params: { id: "builtin:default" }, expect: 200 });
  assert.equal(uv.json().edges.length, 4 * uv.json().edge_count);
  assert.ok(isPng((await api("GET", "/models/{id}/uv-layout", { params: { id: "builtin:default" }, query: "format=png&size=64", expect: 200 })).bytes));
  await api("GET", "/models/{id}/uv-layout", { params: { id: "builtin:default" }, query: "format=svg", expect: 422 });
  // No UVs: auto is the generated layout; the model's own is refused.
  assert.equal((await api("GET", "/models/{id}/uv-layout", { params: { id: uploaded.id }, expect: 200 })).json().layout, "generated");
  await api("GET", "/models/{id}/uv-layout", { params: { id: uploaded.id }, query: "layout=model", expect: 422 });
  await api("DELETE", "/models/{id}", { params: { id: uploaded.id }, expect: 204 });
  await api("DELETE", "/models/{id}", { params: { id: uploadedGltf.id }, expect: 204 });
  await api("DELETE", "/models/{id}", { params: { id: "builtin:default" }, expect: 409 });

  // patterns
  const png = readFileSync(join(source, "patterns/crease.png"));
  const pattern = (await api("POST", "/patterns", { query: "name=my%20crease", body: { raw: png, type: "image/png" }, expect: 201 })).json();
  assert.equal((await api("POST", "/patterns", { body: { raw: png, type: "image/png" }, expect: 200 })).json().id, pattern.id);
  await api("POST", "/patterns", { body: { raw: "junk", type: "image/png" }, expect: 415 });
  const patterns = (await api("GET", "/patterns", { expect: 200 })).json().patterns;
  assert.ok(patterns.some((p) => p.builtin) && patterns.some((p) => p.id === pattern.id));
  assert.ok(isPng((await api("GET", "/patterns/{id}/image", { params: { id: pattern.id }, query: "size=32", expect: 200 })).bytes));
  await api("GET", "/patterns/{id}/image", { params: { id: "crease" }, query: "size=0", expect: 422 });
  await api("DELETE", "/patterns/{id}", { params: { id: pattern.id }, expect: 204 });
  await api("DELETE", "/patterns/{id}", { params: { id: "crease" }, expect: 409 });
  await api("DELETE", "/patterns/{id}", { params: { id: pattern.id }, expect: 404 });

  // environments: a 16 × 8 Radiance sky of radiance (1, 0.5, 0.25) (RGBE 128, 64, 32, exponent 129)
  const sky = Buffer.concat([Buffer.from("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n"),
    Buffer.from(Array.from({ length: 16 * 8 }, () => [128, 64, 32, 129]).flat())]);
  const env = (await api("POST", "/environments", { query: "name=sky", body: { raw: sky, type: "image/vnd.radiance" }, expect: 201 })).json();
  assert.equal((await api("POST", "/environments", { body: { raw: sky, type: "application/octet-stream" }, expect: 200 })).json().id, env.id);
  await api("POST", "/environments", { body: { raw: png, type: "image/png" }, expect: 415 });
  const envs = (await api("GET", "/environments", { expect: 200 })).json().environments;
  assert.deepEqual(envs.map((e) => e.id), ["builtin:studio", env.id]);
  await api("DELETE", "/environments/{id}", { params: { id: "builtin:studio" }, expect: 409 });
  await api("DELETE", "/environments/{id}", { params: { id: env.id }, expect: 204 });
  await api("DELETE", "/environments/{id}", { params: { id: env.id }, expect: 404 });

  // scenes: the default set (for inspection) and a small document (edits, renders, events)
  const created = await api("POST", "/scenes", { body: { default_patterns: true }, expect: 201 });
  const createdBody = created.json();
  const id = createdBody.id;
  assert.equal(created.headers.get("etag"), '"r1"');
  assert.equal(created.headers.get("location"), `/api/v1/scenes/${id}`);
  const doc = {
    format: "dermis.scene/1", model: "builtin:default", heightmap: { size: [128, 128] },
    placements: [{ id: "elbow_l", pattern: "crease", center: [0.2899, 0.7376], scale: [0.06, 0.04],
                   joint: "forearm.l", axis: "x", theta_min: 0, theta_max: 130 }],
    pose: { animation: "elbow_curl", time: 1.0 }, render: { size: [64, 64], msaa: 1 },
  };
  const sid = (await api("POST", "/scenes", { body: doc, headers: { "X-Dermis-Client": "ana" }, expect: 201 })).json().id;
  const S = { id: sid };
  await api("GET", "/scenes", { expect: 200 });
  await api("GET", "/scenes/{id}", { params: { id }, expect: 200 });
  await api("PUT", "/scenes/{id}", { params: S, body: { ...doc, placements: [{ ...doc.placements[0], h: 1.5 }] }, expect: 200 });
  await api("POST", "/scenes/{id}/placements", { params: S, expect: 201, body:
    { id: "biceps_l", pattern: "round_bulge", center: [0.2878, 0.6612], scale: [0.045, 0.065], joint: "forearm.l",
      axis: "x", theta_min: 0, theta_max: 130, target: "displacement" } });
  await api("PATCH", "/scenes/{id}/placements/{pid}", { params: { ...S, pid: "elbow_l" }, body: { h: 1.2, label: "left elbow", rotation: null }, expect: 200 });
  await api("PUT", "/scenes/{id}/placements", { params: S, body: ["biceps_l", "elbow_l"], expect: 200 });
  await api("PUT", "/scenes/{id}/pose", { params: S, body: { animation: "elbow_curl", time: 0.5 }, expect: 200 });
  await api("PATCH", "/scenes/{id}/pose", { params: S, body: { animation: null, joints: { "forearm.l": { axis_angles: { x: 90 } } } }, expect: 200 });
  const afterDelete = (await api("DELETE", "/scenes/{id}/placements/{pid}", { params: { ...S, pid: "biceps_l" }, expect: 200 })).json();
  assert.deepEqual(afterDelete.scene.placements.map((p) => p.id), ["elbow_l"]);
  await api("GET", "/scenes/{id}", { params: S, query: "revision=1", expect: 200 });
  await api("GET", "/scenes/{id}/revisions", { params: S, query: "limit=3", expect: 200 });
  await api("POST", "/scenes/{id}/revert", { params: S, body: { revision: 2 }, expect: 200 });
  // The default set has elbow_l's twin already: 409 naming it; the small scene gets one (201).
  await api("POST", "/scenes/{id}/placements/{pid}/mirror", { params: { id, pid: "elbow_l" }, expect: 409 });
  await api("POST", "/scenes/{id}/placements/{pid}/mirror", { params: { ...S, pid: "elbow_l" }, expect: 201 });
  await api("POST", "/scenes/{id}/placements/{pid}/mirror", { params: { ...S, pid: "elbow_l" }, query: "update=true", expect: 200 });
  // SPEC 8: proposals (a preview, then applied on an empty scene of the default character) and a
  // transfer of the default set onto it (a preview, then applied).
  const empty = { format: "dermis.scene/1", model: "builtin:default", heightmap: { size: [128, 128] }, placements: [] };
  const P = { id: (await api("POST", "/scenes", { body: empty, expect: 201 })).json().id };
  const proposed = (await api("POST", "/scenes/{id}/propose", { params: P, expect: 200 })).json();
  assert.ok(proposed.proposals.length > 0, "proposals for the default character");
  const applied = (await api("POST", "/scenes/{id}/propose", { params: P, query: "apply=true", expect: 201 })).json();
  assert.equal(applied.applied.length, proposed.proposals.length);
  await api("POST", "/scenes/{id}/propose", { params: P, query: "apply=true", expect: 409 });
  await api("POST", "/scenes/{id}/propose", { params: P, query: "apply=maybe", expect: 422 });
  await api("POST", "/scenes/{id}/transfer", { params: P, query: "apply=false", body: { from: id }, expect: 200 });
  await api("POST", "/scenes/{id}/transfer", { params: P, body: { from: id, joint_map: { "forearm.l": "forearm.l" } }, expect: 201 });
  await api("POST", "/scenes/{id}/transfer", { params: P, body: { from: "s_0000000000000000" }, expect: 404 });
  await api("POST", "/scenes/{id}/transfer", { params: P, body: { from: id, bogus: 1 }, invalidRequest: true, expect: 422 });
  await api("PATCH", "/scenes/{id}/pose", { params: { id }, body: { time: 0.25 }, expect: 200 });
  await api("POST", "/scenes/{id}/presence", { params: S, body: { client: "ben", selection: ["elbow_l"], color: "#0af" }, expect: 200 });
  await api("GET", "/scenes/{id}/presence", { params: S, expect: 200 });

  // inspection (CPU)
  await api("GET", "/scenes/{id}/probe", { params: { id }, query: "u=0.29&v=0.737", expect: 200 });
  await api("GET", "/scenes/{id}/activation", { params: { id }, query: "clip=squat&fps=10", expect: 200 });
  await api("GET", "/scenes/{id}/lint", { params: { id }, expect: 200 });
  await api("GET", "/scenes/{id}/pick", { params: { id }, query: "x=128&y=100&width=256&height=256", expect: 200 });
  await api("GET", "/scenes/{id}/pick", { params: { id }, query: "x=1&y=1&width=256&height=256", expect: 200 });
  for (const q of ["placement=clavicle_r&steps=4&format=json", "clip=squat&steps=4&format=json", "clip=squat&placement=knee_l&steps=4&format=json"])
    await api("GET", "/scenes/{id}/sweep", { params: { id }, query: q, expect: 200 });
  const sheet = await api("GET", "/scenes/{id}/sweep", { params: { id }, query: "placement=elbow_l&steps=4&size=48", expect: 200 });
  assert.ok(isPng(sheet.bytes));
  await api("GET", "/scenes/{id}/sweep", { params: { id }, query: "placement=elbow_l&steps=0", expect: 422 });
  // the 3D view: focus (the editor's F) and the turntable (an animated WebP)
  const focus = (await api("GET", "/scenes/{id}/focus", { params: { id }, query: "placement=elbow_l&time=0.5", expect: 200 })).json();
  await api("GET", "/scenes/{id}/focus", { params: { id }, query: "placement=nope", expect: 404 });
  const turntable = await api("GET", "/scenes/{id}/turntable", { params: { id }, query: `placement=elbow_l&frames=4&size=64&target=${focus.target.join(",")}&distance=${focus.distance}`, expect: 200 });
  assert.equal(turntable.bytes.subarray(8, 12).toString(), "WEBP");
  await api("GET", "/scenes/{id}/turntable", { params: { id }, query: "placement=elbow_l&frames=2", expect: 422 });
  const noTexture = await api("GET", "/models/{id}/texture", { params: { id: "builtin:default" }, expect: 404 });
  assert.equal(noTexture.json().error.code, "no_texture");
  const byUv = await api("GET", "/scenes/{id}/pick", { params: { id }, query: "u=0.29&v=0.737", expect: 200 });
  assert.equal(byUv.json().hit, true);
  await api("GET", "/scenes/{id}/pick", { params: { id }, query: "u=1.5&v=0.5", expect: 422 });
  // the texture view's outline of a footprint (SPEC 8): a UV placement's rectangle; a surface decal
  // at the pick's anchor (added to the small scene, then removed), its hit test; errors
  const outline = "/scenes/{id}/placements/{pid}/outline";
  const rect = (await api("GET", outline, { params: { id, pid: "elbow_l" }, expect: 200 })).json();
  assert.equal(rect.projection, "uv");
  assert.equal(rect.segments.length, 4);
  await api("POST", "/scenes/{id}/placements", { params: S, expect: 201, body:
    { id: "decal", pattern: "round_bulge", joint: "forearm.l", projection: "surface", anchor: byUv.json().anchor, size: [0.1, 0.1] } });
  const [pu, pv] = byUv.json().uv;
  const decal = (await api("GET", outline, { params: { ...S, pid: "decal" }, query: `u=${pu}&v=${pv}`, expect: 200 })).json();
  assert.equal(decal.projection, "surface");
  assert.ok(decal.pieces >= 1 && decal.segments.length >= 4 && decal.hit === true, JSON.stringify(decal).slice(0, 300));
  await api("GET", outline, { params: { ...S, pid: "nope" }, expect: 404 });
  await api("GET", outline, { params: { ...S, pid: "decal" }, query: "u=0.5", expect: 422 });
  await api("GET", outline, { params: { ...S, pid: "decal" }, query: "revision=99999", expect: 404 });
  await api("DELETE", "/scenes/{id}/placements/{pid}", { params: { ...S, pid: "decal" }, expect: 200 });
  const drivers = await api("GET", "/scenes/{id}/drivers", { params: { id }, query: "time=0.5", expect: 200 });
  assert.ok(drivers.json().placements.length > 0 && drivers.json().camera.distance > 0);
  await api("GET", "/scenes/{id}/drivers", { params: { id }, query: "revision=99999", expect: 404 });

  // renders
  assert.ok(isPng((await api("GET", "/scenes/{id}/frame", { params: S, expect: 200 })).bytes));
  const jpeg = await api("GET", "/scenes/{id}/frame", { params: S, query: "format=jpeg&width=48&height=32&time=0.3", expect: 200 });
  assert.ok(isJpeg(jpeg.bytes));
  assert.ok(jpeg.headers.get("x-dermis-backend"));
  await api("GET", "/scenes/{id}/frame", { params: S, query: "format=gif", expect: 422 });
  // The same frame with its parameters in a JSON body (a preview too large for the request line).
  const posted = await api("POST", "/scenes/{id}/frame", { params: S, body: { format: "jpeg", width: 48, height: 32, time: 0.3 }, expect: 200 });
  assert.ok(posted.bytes.equals(jpeg.bytes), "POST frame = GET frame");
  await api("POST", "/scenes/{id}/frame", { params: S, body: { bogus: 1 }, invalidRequest: true, expect: 422 });
  const diff = await api("GET", "/scenes/{id}/frame-diff", { params: S, query: "against=off", expect: 200 });
  assert.match(diff.headers.get("x-dermis-changed-pixels") || "", /^[0-9]+$/);
  for (const [map, format, media] of [["bump", "", "image/png"], ["displacement", "format=f32", "application/octet-stream"],
                                      ["normal", "format=exr", "image/x-exr"]]) {
    const m = await api("GET", "/scenes/{id}/heightmaps/{map}", { params: { ...S, map }, query: format, expect: 200 });
    assert.equal(m.media, media, `${map} ${format}`);
  }
  await api("GET", "/scenes/{id}/heightmaps/{map}", { params: { ...S, map: "normal" }, query: "format=f32", expect: 422 });
  const batchBody = { scene: doc, frames: [{ time: 0.5 }, { pose: { animation: "elbow_curl", time: 1.0 } }], format: "jpeg" };
  const batch = await api("POST", "/render", { body: batchBody, expect: 200 });
  assert.equal(batch.headers.get("x-dermis-frames"), "2");
  const parts = batch.bytes.toString("latin1").split("--dermis-frame-boundary").slice(1, -1);
  assert.equal(parts.length, 2);
  parts.forEach((p, k) => {
    assert.match(p, /Content-Type: image\/jpeg\r\n/);
    assert.match(p, new RegExp(`X-Dermis-Frame: ${k}\r\n`));
  });
  await api("POST", "/render", { body: { scene: doc, frames: [] }, invalidRequest: true, expect: 422 });

  // events: hello, a change, presence; the scene's deletion ends the stream
  const stream = await fetch(`${base}/scenes/${sid}/events`);
  assert.equal(stream.status, 200);
  assert.equal(mediaType(stream.headers.get("content-type")), "text/event-stream");
  called.add("GET /scenes/{id}/events");
  const reader = stream.body.getReader();
  let streamText = "";
  const readUntil = async (pred) => {
    const deadline = Date.now() + 20000;
    while (!pred(streamText)) {
      assert.ok(Date.now() < deadline, "event stream: timed out; got " + streamText);
      const { value, done } = await reader.read();
      if (done) break;
      streamText += Buffer.from(value).toString("utf8");
    }
  };
  await readUntil((t) => t.includes("event: hello"));
  await api("PATCH", "/scenes/{id}/placements/{pid}", { params: { ...S, pid: "elbow_l" }, headers: { "X-Dermis-Client": "ana" }, body: { h: 1.1 }, expect: 200 });
  await api("POST", "/scenes/{id}/presence", { params: S, body: { client: "ben", selection: [] }, expect: 200 });
  await api("PATCH", "/scenes/{id}/pose", { params: S, body: { time: 0.7 }, expect: 200 });
  await readUntil((t) => (t.match(/event: change/g) || []).length >= 2 && t.includes("event: presence"));
  await api("DELETE", "/scenes/{id}", { params: S, headers: { "If-Match": "*" }, expect: 204 });
  await readUntil((t) => t.includes('"type":"deleted"'));
  const events = sseEvents(streamText.slice(0, streamText.lastIndexOf("\n\n") + 2));
  for (const e of events) checkEvent("GET /scenes/{id}/events", e);
  assert.deepEqual(events.map((e) => e.data.type), ["hello", "placement_updated", "presence", "pose", "deleted"]);
  await reader.cancel().catch(() => {});

  // error answers, each against its status's documented schema
  await api("GET", "/scenes/{id}", { params: { id: "s_0000000000000000" }, expect: 404 });
  await api("GET", "/scenes/{id}", { params: { id }, query: "revision=x", expect: 422 });
  await api("POST", "/scenes", { body: { raw: '{"format":', type: "application/json" }, expect: 400 });
  await api("PUT", "/scenes/{id}", { params: { id }, body: { raw: "{}", type: "text/plain" }, expect: 415 });
  const badDoc = { ...doc, placements: [{ ...doc.placements[0], h: -1 }] };
  const invalid = (await api("POST", "/scenes", { body: badDoc, invalidRequest: true, expect: 422 })).json();
  assert.equal(invalid.error.field, "/placements/0/h");
  await api("POST", "/scenes/{id}/placements", { params: { id }, body: { center: [0.5, 0.5] }, invalidRequest: true, expect: 422 });
  await api("PATCH", "/scenes/{id}/pose", { params: { id }, body: { time: -1 }, invalidRequest: true, expect: 422 });
  await api("POST", "/scenes/{id}/presence", { params: { id }, body: { client: "ana", shape: "circle" }, invalidRequest: true, expect: 422 });
  // Based on r1, from before that pose edit: a conflict (an edit of something unchanged since would be rebased).
  const stale = (await api("PATCH", "/scenes/{id}/pose", { params: { id }, headers: { "If-Match": '"r1"' }, body: {}, expect: 412 })).json();
  assert.equal(stale.revision, 2);
  await api("DELETE", "/scenes/{id}", { params: { id }, headers: { "If-Match": "r2" }, expect: 400 });
  await api("DELETE", "/scenes/{id}", { params: { id }, expect: 204 });

  // every operation of the document was called live
  const uncalled = [...operations.keys()].filter((k) => !called.has(k));
  assert.deepEqual(uncalled, [], "operations the test never called");

  // --- the schemas fail on wrong answers and wrong requests
  const schemaOf = (key, status, media = "application/json") => operations.get(key).responses[status].validators.get(media);
  const sceneValidator = schemaOf("POST /scenes", "201");
  const wrong = (v, value, what) => assert.ok(!v(value), `${what} passed`);
  const noRevision = { ...createdBody };
  delete noRevision.revision;
  wrong(sceneValidator, noRevision, "a scene answer without its revision");
  const badPlacement = structuredClone(createdBody);
  badPlacement.scene.placements[0].h = -1;
  wrong(sceneValidator, badPlacement, "a scene answer with h < 0");
  const unknownField = structuredClone(createdBody);
  unknownField.scene.placements[0].colour = "red";
  wrong(sceneValidator, unknownField, "a scene answer with a placement with an unknown field");
  const missingLabel = structuredClone(createdBody);
  delete missingLabel.scene.placements[0].label;
  wrong(sceneValidator, missingLabel, "a scene answer with a placement without its label");
  const errorValidator = componentSchema("Error");
  wrong(errorValidator, { error: { message: "no code", field: "" } }, "an error without its code");
  wrong(errorValidator, { error: { code: "oops", message: "", field: "" } }, "an error with an unknown code");
  const summary = { builtin: false, bytes: 50116, clips: 1, has_texture: false, has_uvs: false, id: "m_825650b7acc9d69d", joint_count: 19, joints: 19, name: "RiggedFigure", triangles: 256 };
  assert.ok(componentSchema("ModelSummary")(summary));
  wrong(schemaOf("GET /models", "200"), { models: [{ ...summary, triangles: "256" }] }, "a model summary with a string triangle count");
  wrong(schemaOf("POST /models", "201"), { ...summary, uvs: true }, "a model summary with an unknown field");
  wrong(schemaOf("GET /patterns", "200"), { patterns: [{ id: "crease", name: "crease", builtin: true, width: 512, height: 512 }] }, "a built-in pattern without its manifest entry");
  const info = (await call("GET", "/info")).json();
  delete info.limits.max_upload_bytes;
  wrong(schemaOf("GET /info", "200"), info, "an info without max_upload_bytes");
  wrong(schemaOf("GET /health", "200"), { status: "fine" }, "a health answer that is not ok");
  wrong(eventValidator, { type: "placement_updated", scene: "s", revision: 2, client: "", op: "x" }, "a change event without its placement");
  wrong(eventValidator, { type: "party", scene: "s" }, "an event of an unknown type");
  const req = (key) => operations.get(key).request.get("application/json");
  wrong(req("PATCH /scenes/{id}/placements/{pid}"), { h: "high" }, "a placement patch with a string h");
  wrong(req("PUT /scenes/{id}/placements"), ["a", "a"], "an order listing a placement twice");
  wrong(req("POST /render"), { scene: doc, frames: [{}] }, "a batch frame with neither time nor pose");
  wrong(req("POST /scenes"), { default_patterns: false }, "a create request that is neither a document nor default_patterns");
  console.log(`OpenApiHttpTest: ${examples.length + 1} documented scenes, ${operations.size} operations all called live, ` +
              `${compiled.size} schemas, ${documentedExamples.size} documented examples valid, wrong answers refused`);
} catch (e) {
  failed = true;
  console.error(e);
} finally {
  server.stop();
}
process.exit(failed ? 1 : 0);
