// Shared by the live view's Node tests (and tools/bench_live.js): start `ademono run --live`, find its port, read the run's
// outputs. Environment: ADEMONO_CLI (the binary), ADEMONO_SHARED_DIR (../shared), ADEMONO_NODE_MODULES
// (.deps/foxglove/node_modules, scripts/setup.sh), ADEMONO_LIVE_PORT (optional: a port of the
// caller's choosing; default 0, any free port, read back from the run's stderr),
// ADEMONO_LIVE_FRAMES (default 0:200).
'use strict';
const assert = require('assert');
const childProcess = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const ROOT = path.resolve(__dirname, '..', '..');
const CLI = process.env.ADEMONO_CLI || path.join(ROOT, 'build', 'release', 'bin', 'ademono');
const SHARED = process.env.ADEMONO_SHARED_DIR || path.resolve(ROOT, '..', 'shared');
const NODE_MODULES = process.env.ADEMONO_NODE_MODULES || path.join(ROOT, '.deps', 'foxglove', 'node_modules');
const DATASET = '7scenes:' + path.join(SHARED, 'data', '7scenes-seq-a');

function need(name) {
  return require(path.join(NODE_MODULES, name));
}

function port() {
  const args = process.argv.slice(2);
  const i = args.indexOf('--port');
  if (i >= 0) return Number(args[i + 1]);
  return Number(process.env.ADEMONO_LIVE_PORT || 0);
}

function tempDir(name) {
  return fs.mkdtempSync(path.join(os.tmpdir(), 'ademono-live-' + name + '-'));
}

// The run's base arguments: 200 frames of seq-a with sensor depth.
function runArgs(out) {
  const frames = process.env.ADEMONO_LIVE_FRAMES || '0:200';
  return ['run', '--dataset', DATASET, '--depth', 'sensor', '--frames', frames, '--out', out];
}

// With { timed: true } the run goes through /usr/bin/time, whose last stderr line is
// "CPU USER SYS" (seconds of the whole process): see cpuSeconds().
function command(args, options) {
  if (options && options.timed) return ['/usr/bin/time', ['-f', 'CPU %U %S', CLI].concat(args)];
  return [CLI, args];
}
function cpuSeconds(stderr) {
  const m = /CPU ([0-9.]+) ([0-9.]+)\s*$/.exec(stderr);
  return m ? Number(m[1]) + Number(m[2]) : null;
}

// Runs to the end without a live view; returns the output folder (and with { timed: true },
// {out, cpu}).
function runPlain(out, options) {
  const [cmd, args] = command(runArgs(out), options);
  const r = childProcess.spawnSync(cmd, args, { encoding: 'utf8', timeout: 600000 });
  assert.strictEqual(r.status, 0, 'plain run failed: ' + r.stderr);
  return options && options.timed ? { out, cpu: cpuSeconds(r.stderr) } : out;
}

// Starts a run with --live and `extra` options; returns {proc, url, wsUrl, exited}. `url`
// resolves once the run has printed where it serves.
function startLive(out, extra, options) {
  const [cmd, args] = command(runArgs(out).concat(['--live', '127.0.0.1:' + port()], extra || []),
    options);
  const proc = childProcess.spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let stderr = '';
  let stdout = '';
  proc.stdout.on('data', (d) => { stdout += d; });
  const url = new Promise((resolve, reject) => {
    proc.stderr.on('data', (d) => {
      stderr += d;
      const m = /live view at (http:\/\/[^\s]+\/)/.exec(stderr);
      if (m) resolve(m[1]);
    });
    proc.on('exit', () => reject(new Error('run ended before serving: ' + stderr)));
  });
  const exited = new Promise((resolve) => {
    proc.on('exit', (code, signal) => resolve({ code, signal, stderr, stdout }));
  });
  return { proc, url, exited, wsUrl: url.then((u) => u.replace(/^http:/, 'ws:')) };
}

function withTimeout(promise, ms, what) {
  let timer;
  return Promise.race([
    promise.finally(() => clearTimeout(timer)),
    new Promise((_, reject) => { timer = setTimeout(() => reject(new Error('timed out: ' + what)), ms); }),
  ]);
}

// trajectory.tum / keyframes.tum rows: [t, tx, ty, tz, qx, qy, qz, qw].
function readTum(file) {
  return fs.readFileSync(file, 'utf8').split('\n')
    .filter((l) => l.trim() && !l.startsWith('#'))
    .map((l) => l.trim().split(/\s+/).map(Number));
}

function plyVertexCount(file) {
  const m = /element vertex (\d+)/.exec(fs.readFileSync(file, 'utf8').slice(0, 400));
  assert(m, file + ': no vertex count');
  return Number(m[1]);
}

function sameFile(a, b) {
  return Buffer.compare(fs.readFileSync(a), fs.readFileSync(b)) === 0;
}

// Counts checks for the closing "N passed, N failed" line.
class Checks {
  constructor() { this.passed = 0; this.failed = 0; }
  check(ok, what) {
    if (ok) { this.passed++; } else { this.failed++; console.error('FAILED: ' + what); }
  }
  finish() {
    console.log(this.passed + ' passed, ' + this.failed + ' failed');
    process.exit(this.failed === 0 ? 0 : 1);
  }
}

module.exports = {
  CLI, SHARED, need, tempDir, runArgs, runPlain, startLive, withTimeout, readTum, plyVertexCount,
  sameFile, Checks, path, fs, cpuSeconds,
};
