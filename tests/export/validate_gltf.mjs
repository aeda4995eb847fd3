// Runs the Khronos glTF validator (npm package gltf-validator) on glTF files and prints each
// report. Exits 1 when any file has an error (with --no-warnings: or a warning; with
// --require-animation: or no animation), 2 when the validator is not installed or a file cannot
// be read.
// Usage: node validate_gltf.mjs [--no-warnings] [--require-animation] NPM_PREFIX FILE...
//   NPM_PREFIX: the folder given to `npm install --prefix` (scripts/test.sh uses build/node).
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

const args = process.argv.slice(2);
const flags = new Set();
while (args.length > 0 && args[0].startsWith('--')) flags.add(args.shift());
const requireAnimation = flags.delete('--require-animation');
const noWarnings = flags.delete('--no-warnings');
const [prefix, ...files] = args;
if (flags.size > 0 || !prefix || files.length === 0) {
  console.error('usage: node validate_gltf.mjs [--no-warnings] [--require-animation] ' +
                'NPM_PREFIX FILE...');
  process.exit(2);
}

const require = createRequire(import.meta.url);
let validator;
try {
  validator = require(path.resolve(prefix, 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error(`validate_gltf: gltf-validator is not installed under ${prefix} ` +
                `(run scripts/test.sh, or npm install --prefix ${prefix} ` +
                `gltf-validator@2.0.0-dev.3.10): ${e.message}`);
  process.exit(2);
}

let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = fs.readFileSync(file);
  } catch (e) {
    console.error(`validate_gltf: cannot read ${file}: ${e.message}`);
    process.exit(2);
  }
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
      fs.promises.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)))
        .then((data) => new Uint8Array(data)),
  });
  const issues = report.issues;
  console.log(JSON.stringify({ file, validator: report.validatorVersion, issues,
                               info: report.info }, null, 2));
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints`);
  if (issues.numErrors > 0) failed = true;
  if (noWarnings && issues.numWarnings > 0) {
    console.error(`${file}: expected no warnings`);
    failed = true;
  }
  if (requireAnimation && !(report.info && report.info.animationCount > 0)) {
    console.error(`${file}: expected at least one animation`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
