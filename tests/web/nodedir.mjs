// Where the web checks find their npm packages: $SFB_NODE_DIR, else <repo>/build/node (what
// `make deps-web` fills with `npm ci` from tests/web/package.json and package-lock.json).
import { createRequire } from 'node:module';
import { existsSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

export const repoRoot = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const nodeDir = resolve(process.env.SFB_NODE_DIR || join(repoRoot, 'build', 'node'));
export const nodeModules = join(nodeDir, 'node_modules');

// require() of an installed package, or null when it is not installed.
export function requirePackage(name) {
  if (!existsSync(join(nodeModules, name, 'package.json'))) return null;
  return createRequire(join(nodeDir, 'package.json'))(name);
}

export function missingPackage(name) {
  return `npm package ${name} not found under ${nodeModules} (install it with: make deps-web)`;
}
