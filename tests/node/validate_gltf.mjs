// Validates .gltf and .glb files with the Khronos glTF-Validator.
// Prints one line per file; exits 1 if any file has an error or a warning.
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

let bad = 0;
for (const path of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(path));
  const report = await validator.validateBytes(bytes, { maxIssues: 20 });
  const { numErrors, numWarnings, numInfos, messages } = report.issues;
  console.log(`${path}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
  if (numErrors || numWarnings) {
    bad++;
    for (const m of messages.filter((m) => m.severity <= 1))
      console.log(`  ${m.severity ? 'warning' : 'error'} ${m.code} at ${m.pointer ?? ''}: ${m.message}`);
  }
}
process.exit(bad ? 1 : 0);
