// Validates GLB files with the Khronos glTF validator.
//
// Usage: node validate.mjs FILE.glb [FILE.glb ...]
// Prints one line per file with its error, warning, info and hint counts, then the messages of
// any errors or warnings. Exit status: 0 when every file is clean, 1 when any file has an error
// or a warning, 2 on a usage or I/O error (including an asset the validator cannot read).
// Install with `npm ci --prefix tools/gltf-validator` from the repository root.

import { readFile } from "node:fs/promises";
import { basename } from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
let validator;
try {
  validator = require("gltf-validator");
} catch (e) {
  console.error(
    `cannot load gltf-validator (${e.message}); run \`npm ci --prefix tools/gltf-validator\``,
  );
  process.exit(2);
}

const SEVERITY = ["error", "warning", "info", "hint"];

async function validateFile(path) {
  const bytes = new Uint8Array(await readFile(path));
  const report = await validator.validateBytes(bytes, {
    uri: basename(path),
    format: "glb",
    maxIssues: 0,
    writeTimestamp: false,
  });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  console.log(
    `${path}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`,
  );
  for (const m of messages) {
    if (m.severity <= 1) {
      const where = m.pointer ?? (m.offset !== undefined ? `byte ${m.offset}` : "");
      console.log(`  ${SEVERITY[m.severity]} ${m.code} ${where}: ${m.message}`);
    }
  }
  return numErrors + numWarnings === 0;
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node validate.mjs FILE.glb [FILE.glb ...]");
  process.exit(2);
}

let clean = true;
for (const file of files) {
  try {
    clean = (await validateFile(file)) && clean;
  } catch (e) {
    console.error(`${file}: ${e?.message ?? e}`);
    process.exit(2);
  }
}
process.exit(clean ? 0 : 1);
