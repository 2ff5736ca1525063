// Validates glTF / GLB files with the Khronos glTF validator.
// Usage: node validate_gltf.mjs FILE...   Exit 0 when no file has an error,
// 1 otherwise, 77 (ctest "skipped") when the validator is not installed.
import fs from 'node:fs';

let validator;
try {
  validator = (await import('gltf-validator')).default;
} catch (e) {
  console.log('SKIPPED: gltf-validator is not installed (run npm ci in tests/js)');
  process.exit(77);
}

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), { maxIssues: 100 });
  const { numErrors, numWarnings } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ` +
              `${report.info ? report.info.totalTriangleCount : '?'} triangles`);
  for (const m of report.issues.messages) console.log(`  ${m.severity === 0 ? 'error' : 'note'} ${m.code}: ${m.message} ${m.pointer || ''}`);
  if (numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
