// FarmK8sTest — the Kubernetes manifests of farm/k8s validate offline, without a cluster:
//   * every YAML document (farm/k8s/**/*.yaml, kustomizations aside) is checked against the schema
//     of its apiVersion/kind from the npm package kubernetes-models (an unknown apiVersion/kind
//     fails, as does a wrong type or a missing required field; misspelled optional field names are
//     NOT caught by those schemas — the cross-checks below cover the fields we rely on);
//   * kustomizations name files that exist; the GPU patch, merged into the base Deployment the way
//     kustomize's strategic merge does for these fields (containers by name), still validates and
//     asks for one nvidia.com/gpu;
//   * cross-checks: probes on /api/v1/health of the named port, the token from the Secret that is
//     shipped, Service and HPA point at the Deployment, the Job is Indexed with
//     `--shard auto/<completions>`, its volumes name the shipped PVC and ConfigMap, the ConfigMap's
//     scene is a dermis.scene/1 document;
//   * the validator is not vacuous: broken copies (a string port, an unknown kind) are refused.
// Usage: node validate.test.mjs <source dir>            (exit 0 = pass)
//        node validate.test.mjs <source dir> --job-command   (prints the Job's command as JSON)
import { parseAllDocuments } from "yaml";
import { readFileSync, readdirSync, existsSync, statSync } from "node:fs";
import { join, dirname, relative } from "node:path";
import assert from "node:assert/strict";

const [source, mode] = process.argv.slice(2);
const root = join(source, "farm", "k8s");

const yamlFiles = (dir) => readdirSync(dir).flatMap((n) => {
  const p = join(dir, n);
  return statSync(p).isDirectory() ? yamlFiles(p) : n.endsWith(".yaml") ? [p] : [];
});
const docsOf = (file) => parseAllDocuments(readFileSync(file, "utf8")).map((d) => {
  if (d.errors.length) throw new Error(`${file}: ${d.errors[0].message}`);
  return d.toJS();
}).filter(Boolean);

/// The kubernetes-models class for a document's apiVersion/kind (throws when there is none).
async function modelFor(doc) {
  assert.ok(doc.apiVersion && doc.kind, "apiVersion and kind");
  const [group, version] = doc.apiVersion.includes("/") ? doc.apiVersion.split("/") : ["", doc.apiVersion];
  let mod;
  try {
    mod = await import(`kubernetes-models/${group ? group + "/" : ""}${version}`);
  } catch {
    throw new Error(`unknown apiVersion ${doc.apiVersion}`);
  }
  if (!mod[doc.kind]) throw new Error(`unknown kind ${doc.kind} in ${doc.apiVersion}`);
  return mod[doc.kind];
}
async function validate(doc) {
  const Model = await modelFor(doc);
  new Model(doc).validate(); // throws with the schema's message
}

/// Strategic merge of `patch` into `base` for what the GPU patch uses: maps merge, lists of
/// objects with a `name` merge by name, other lists and scalars are replaced.
function merge(base, patch) {
  if (Array.isArray(patch)) {
    if (!Array.isArray(base) || !patch.every((p) => p && typeof p === "object" && "name" in p)) return structuredClone(patch);
    const out = structuredClone(base);
    for (const p of patch) {
      const i = out.findIndex((b) => b && b.name === p.name);
      if (i < 0) out.push(structuredClone(p)); else out[i] = merge(out[i], p);
    }
    return out;
  }
  if (patch && typeof patch === "object") {
    const out = base && typeof base === "object" && !Array.isArray(base) ? structuredClone(base) : {};
    for (const [k, v] of Object.entries(patch)) out[k] = merge(out[k], v);
    return out;
  }
  return patch;
}

const files = yamlFiles(root);
const all = [];
for (const f of files) for (const doc of docsOf(f)) all.push({ file: relative(source, f), doc });
const find = (kind, name) => all.find((d) => d.doc.kind === kind && (!name || d.doc.metadata.name === name) && !d.file.includes("/gpu/"));

const job = find("Job").doc;
const jobContainer = job.spec.template.spec.containers[0];
if (mode === "--job-command") {
  process.stdout.write(JSON.stringify({ command: [...jobContainer.command, ...jobContainer.args],
                                        completions: job.spec.completions,
                                        mounts: jobContainer.volumeMounts.map((m) => m.mountPath) }) + "\n");
  process.exit(0);
}

let checks = 0;
const check = async (what, fn) => { await fn(); ++checks; console.log(`ok  ${what}`); };

for (const { file, doc } of all) {
  if (doc.kind === "Kustomization") {
    await check(`${file}: kustomization names existing files`, () => {
      for (const r of [...(doc.resources || []), ...(doc.patches || []).map((p) => p.path)]) {
        assert.ok(existsSync(join(source, dirname(file), r)), `${file}: ${r} exists`);
      }
    });
    continue;
  }
  if (file.includes("/gpu/")) continue; // a patch: validated merged below
  await check(`${file}: ${doc.apiVersion} ${doc.kind} ${doc.metadata.name} validates`, () => validate(doc));
}

const deployment = find("Deployment", "dermis").doc;
await check("the GPU patch merged into the Deployment validates and asks for a GPU", async () => {
  const patch = all.find((d) => d.file.includes("/gpu/") && d.doc.kind === "Deployment").doc;
  const merged = merge(deployment, patch);
  await validate(merged);
  const c = merged.spec.template.spec.containers.find((x) => x.name === "dermis");
  assert.equal(String(c.resources.limits["nvidia.com/gpu"]), "1");
  assert.ok(c.args.includes("egl-device"));
  assert.ok(c.readinessProbe, "the base's probes survive the merge");
  assert.ok(c.env.some((e) => e.name === "DERMIS_TOKEN") && c.env.some((e) => e.name === "NVIDIA_DRIVER_CAPABILITIES"));
});

await check("the Deployment: probes on /api/v1/health, token from the shipped Secret, resources", () => {
  const c = deployment.spec.template.spec.containers[0];
  const port = c.ports.find((p) => p.name === "http");
  for (const probe of [c.readinessProbe, c.livenessProbe]) {
    assert.equal(probe.httpGet.path, "/api/v1/health");
    assert.equal(probe.httpGet.port, "http");
  }
  assert.equal(c.args[c.args.indexOf("--port") + 1], String(port.containerPort));
  const token = c.env.find((e) => e.name === "DERMIS_TOKEN").valueFrom.secretKeyRef;
  const secret = find("Secret", token.name);
  assert.ok(secret && (secret.doc.stringData || secret.doc.data)[token.key] !== undefined, "the Secret and key exist");
  assert.ok(c.resources.requests.cpu && c.resources.requests.memory);
  assert.deepEqual(deployment.spec.selector.matchLabels, deployment.spec.template.metadata.labels);
});

await check("the Service and the autoscaler point at the Deployment", () => {
  const svc = find("Service", "dermis").doc;
  for (const [k, v] of Object.entries(svc.spec.selector)) assert.equal(deployment.spec.template.metadata.labels[k], v);
  assert.equal(svc.spec.ports[0].targetPort, "http");
  const hpa = find("HorizontalPodAutoscaler").doc;
  assert.deepEqual([hpa.spec.scaleTargetRef.kind, hpa.spec.scaleTargetRef.name], ["Deployment", deployment.metadata.name]);
  assert.ok(hpa.spec.minReplicas >= 1 && hpa.spec.maxReplicas >= hpa.spec.minReplicas);
});

await check("the Job is Indexed, shards by JOB_COMPLETION_INDEX over its completions, and mounts what is shipped", () => {
  assert.equal(job.spec.completionMode, "Indexed");
  const args = jobContainer.args;
  assert.equal(args[0], "render");
  assert.equal(args[args.indexOf("--shard") + 1], `auto/${job.spec.completions}`);
  const vols = Object.fromEntries(job.spec.template.spec.volumes.map((v) => [v.name, v]));
  assert.ok(find("PersistentVolumeClaim", vols.frames.persistentVolumeClaim.claimName), "the PVC is shipped");
  const cm = find("ConfigMap", vols.scene.configMap.name);
  assert.ok(cm, "the scene ConfigMap is shipped");
  const scene = JSON.parse(cm.doc.data["scene.json"]);
  assert.equal(scene.format, "dermis.scene/1");
  const sceneMount = jobContainer.volumeMounts.find((m) => m.name === "scene").mountPath;
  assert.equal(args[args.indexOf("--scene") + 1], `${sceneMount}/scene.json`);
  const framesMount = jobContainer.volumeMounts.find((m) => m.name === "frames").mountPath;
  assert.ok(args[args.indexOf("--out") + 1].startsWith(framesMount + "/"));
});

await check("broken manifests are refused (the validator is not vacuous)", async () => {
  const bad = structuredClone(deployment);
  bad.spec.template.spec.containers[0].ports[0].containerPort = "8080";
  await assert.rejects(async () => validate(bad), /must be integer/);
  const noImage = structuredClone(deployment);
  delete noImage.spec.template.spec.containers[0].name;
  await assert.rejects(async () => validate(noImage), /name/);
  await assert.rejects(async () => validate({ ...structuredClone(job), kind: "IndexedJob" }), /unknown kind/);
  await assert.rejects(async () => validate({ ...structuredClone(job), apiVersion: "batch/v9" }), /unknown apiVersion/);
});

console.log(`FarmK8sTest: ${checks} checks passed over ${files.length} files`);
