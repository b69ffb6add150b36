// Runs the Khronos glTF Validator (npm gltf-validator) on one .glb: prints its summary and every message of
// severity error or warning, exits 0 when it reports no error and at most N warnings (--max-warnings N; any
// number without it), 1 otherwise, 2 when the file cannot be read or the arguments are wrong.
// Usage: node viewer/validate.mjs FILE.glb [--max-warnings N]
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

const args = process.argv.slice(2);
let file = args[0];
let maxWarnings = Infinity;
if (args[1] === '--max-warnings' && /^[0-9]+$/.test(args[2] ?? '')) maxWarnings = Number(args[2]);
else if (args.length !== 1) file = undefined;
if (!file) { console.error('usage: node validate.mjs FILE.glb [--max-warnings N]'); process.exit(2); }
let data;
try { data = new Uint8Array(readFileSync(file)); } catch (e) { console.error(`${file}: ${e.message}`); process.exit(2); }
const report = await validator.validateBytes(data, {
  uri: file,
  maxIssues: 1000,
  // the glb embeds everything: an external reference is itself a failure
  externalResourceFunction: (uri) => Promise.reject(new Error(`external resource ${uri} (a glb must embed it)`)),
});
const s = report.issues;
console.log(`${file}: ${s.numErrors} errors, ${s.numWarnings} warnings, ${s.numInfos} infos, ${s.numHints} hints`);
for (const m of s.messages)
  if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
process.exit(s.numErrors === 0 && s.numWarnings <= maxWarnings ? 0 : 1);
