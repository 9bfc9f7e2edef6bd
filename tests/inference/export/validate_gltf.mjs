// Validate a glTF/GLB file with the Khronos glTF-Validator and print its report as JSON.
// Usage: node tests/inference/export/validate_gltf.mjs FILE.glb
// Needs the npm devDependency `gltf-validator` (run `npm ci` at the repository root).
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

const path = process.argv[2];
if (!path) {
  console.error("usage: node validate_gltf.mjs FILE.glb");
  process.exit(2);
}
const bytes = new Uint8Array(await readFile(path));
const report = await validator.validateBytes(bytes, { maxIssues: 100 });
console.log(JSON.stringify(report, null, 1));
