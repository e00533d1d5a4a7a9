// Validates one glTF/GLB file with the Khronos glTF validator (npm "gltf-validator", pinned in
// package.json / package-lock.json).
//   node tests/gltf-validator/validate.mjs FILE.glb [--json]
// Prints the report summary (errors, warnings, infos, hints and the first issues of each kind);
// --json prints the whole report instead. Exit status: 0 when the report has no errors,
// 1 when it has errors, 2 when the file cannot be read or validated at all.
// Needs `npm ci` in this folder first (node_modules is not committed).
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const args = process.argv.slice(2);
const json = args.includes('--json');
const files = args.filter((a) => a !== '--json');
if (files.length !== 1) {
    console.error('usage: node validate.mjs FILE.glb [--json]');
    process.exit(2);
}
const file = files[0];

let bytes;
try {
    bytes = new Uint8Array(await readFile(file));
} catch (e) {
    console.error(`validate.mjs: cannot read ${file}: ${e.message}`);
    process.exit(2);
}

let report;
try {
    report = await validator.validateBytes(bytes, {
        uri: path.basename(file),
        maxIssues: 1000,
        externalResourceFunction: (uri) =>
            readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then(
                (d) => new Uint8Array(d)),
    });
} catch (e) {
    console.error(`validate.mjs: validator failed on ${file}: ${e}`);
    process.exit(2);
}

if (json) {
    console.log(JSON.stringify(report, null, 2));
} else {
    const i = report.issues;
    console.log(`${file}: validator ${report.validatorVersion}`);
    console.log(`  errors ${i.numErrors}, warnings ${i.numWarnings}, infos ${i.numInfos}, ` +
                `hints ${i.numHints}`);
    const severities = ['error', 'warning', 'info', 'hint'];
    for (const m of i.messages.slice(0, 40)) {
        console.log(`  [${severities[m.severity] ?? m.severity}] ${m.code} ${m.pointer ?? ''}: ` +
                    `${m.message}`);
    }
    if (i.messages.length > 40) console.log(`  … ${i.messages.length - 40} more`);
}
process.exit(report.issues.numErrors > 0 ? 1 : 0);
