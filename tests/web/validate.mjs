#!/usr/bin/env node
// Validates glTF 2.0 files with the Khronos glTF-Validator (npm gltf-validator).
//
//   node tests/web/validate.mjs [--json REPORT.json] FILE.glb|FILE.gltf ...
//
// Every file is validated (external resources such as .bin buffers and images are read
// relative to the file; data: URIs are the validator's own business). One line per file:
//   ok FILE (N infos)
//   FAIL FILE: E errors, W warnings
// and, after a FAIL, one indented line per error or warning: SEVERITY CODE POINTER: MESSAGE.
// --json writes {validator, files: [{file, ok, errors, warnings, infos, hints, report}]} with
// the validator's full report per file. Exit status: 0 when every file has 0 errors and 0
// warnings (infos and hints are allowed), 1 otherwise (also for a file that cannot be read or
// parsed), 2 for a usage error, 3 when gltf-validator is not installed (make deps-web).
import { readFile, writeFile } from 'node:fs/promises';
import { dirname, resolve } from 'node:path';
import { requirePackage, missingPackage } from './nodedir.mjs';

const SEVERITY = ['error', 'warning', 'info', 'hint'];

function usage(msg) {
  if (msg) console.error(`validate.mjs: ${msg}`);
  console.error('usage: node tests/web/validate.mjs [--json REPORT.json] FILE.glb|FILE.gltf ...');
  process.exit(2);
}

const args = process.argv.slice(2);
let jsonOut = null;
const files = [];
for (let i = 0; i < args.length; ++i) {
  const a = args[i];
  if (a === '--json') {
    if (i + 1 >= args.length) usage('--json needs a file name');
    jsonOut = args[++i];
  } else if (a === '-h' || a === '--help') {
    console.log('usage: node tests/web/validate.mjs [--json REPORT.json] FILE.glb|FILE.gltf ...\n' +
                'exit 0: no errors and no warnings in any file; 1: some; 2: usage; 3: gltf-validator not installed');
    process.exit(0);
  } else if (a.startsWith('-') && a !== '-') {
    usage(`unknown option ${a}`);
  } else files.push(a);
}
if (files.length === 0) usage('no files given');

const validator = requirePackage('gltf-validator');
if (!validator) { console.error(`validate.mjs: ${missingPackage('gltf-validator')}`); process.exit(3); }

async function validateOne(file) {
  const full = resolve(file);
  let bytes;
  try { bytes = new Uint8Array(await readFile(full)); }
  catch (e) { return { file, ok: false, errors: 1, warnings: 0, infos: 0, hints: 0, failure: `cannot read: ${e.message}` }; }
  const lower = file.toLowerCase();
  const options = {
    uri: file,
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: async (uri) => {
      const path = resolve(dirname(full), decodeURIComponent(uri));
      try { return new Uint8Array(await readFile(path)); }
      catch (e) { throw `cannot read ${uri} (${path}): ${e.code || e.message}`; }
    },
  };
  if (lower.endsWith('.glb')) options.format = 'glb';
  else if (lower.endsWith('.gltf')) options.format = 'gltf';
  let report;
  try { report = await validator.validateBytes(bytes, options); }
  catch (e) { return { file, ok: false, errors: 1, warnings: 0, infos: 0, hints: 0, failure: `the validator refused it: ${e}` }; }
  const is = report.issues;
  return { file, ok: is.numErrors === 0 && is.numWarnings === 0, errors: is.numErrors, warnings: is.numWarnings,
           infos: is.numInfos, hints: is.numHints, report };
}

const results = [];
for (const f of files) {
  const r = await validateOne(f);
  results.push(r);
  if (r.ok) {
    console.log(`ok ${f} (${r.infos} infos)`);
    continue;
  }
  console.log(`FAIL ${f}: ${r.errors} errors, ${r.warnings} warnings`);
  if (r.failure) console.log(`  error IO ${f}: ${r.failure}`);
  for (const m of (r.report ? r.report.issues.messages : []))
    if (m.severity <= 1) {
      const where = m.pointer !== undefined ? m.pointer : m.offset !== undefined ? `@${m.offset}` : '-';
      console.log(`  ${SEVERITY[m.severity]} ${m.code} ${where}: ${m.message}`);
    }
}
if (jsonOut) {
  await writeFile(jsonOut, JSON.stringify({ validator: validator.version(), files: results }, null, 2) + '\n');
}
process.exit(results.every((r) => r.ok) ? 0 : 1);
