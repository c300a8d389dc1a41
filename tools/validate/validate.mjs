// Validates Hairloom exports with third-party readers; run by `make test` (via the CLI
// tests). Usage: node validate.mjs FILE...   (.glb: Khronos glTF-Validator; .ktx2: ktx-parse,
// checked against the manifest.json next to it). Prints one line per file; exits 1 on any
// problem.
import { readFileSync, existsSync } from 'node:fs';
import { dirname, join, basename } from 'node:path';
import validator from 'gltf-validator';
import { read } from 'ktx-parse';

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(readFileSync(file));
  if (file.endsWith('.glb')) {
    const report = await validator.validateBytes(bytes, { uri: basename(file) });
    const { numErrors, numWarnings } = report.issues;
    console.log(`${file}: glTF-Validator ${report.validatorVersion}: ${numErrors} errors, ${numWarnings} warnings`);
    if (numErrors > 0) {
      failed = true;
      for (const m of report.issues.messages.slice(0, 10)) console.log(`  ${m.code}: ${m.message} (${m.pointer ?? ''})`);
    }
  } else if (file.endsWith('.ktx2')) {
    const container = read(bytes);
    const level = container.levels[0];
    const manifestPath = join(dirname(file), 'manifest.json');
    let expected = null;
    if (existsSync(manifestPath)) {
      const manifest = JSON.parse(readFileSync(manifestPath, 'utf8'));
      const name = basename(file, '.ktx2');
      expected = manifest[name];
    }
    const size = [container.pixelWidth, container.pixelHeight, container.pixelDepth];
    let ok = container.levels.length === 1 && level.levelData.byteLength > 0;
    if (expected) {
      ok = ok && expected.size.every((v, i) => v === size[i]);
    }
    console.log(`${file}: ktx-parse: vkFormat ${container.vkFormat}, ${size.join('x')}, ${level.levelData.byteLength} bytes${ok ? '' : ' MISMATCH'}`);
    failed ||= !ok;
  } else {
    console.log(`${file}: no validator for this type`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
