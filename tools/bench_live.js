#!/usr/bin/env node
// The live view's cost on throughput (issue 30): seq-a, all 600 frames, sensor depth, default
// config; runs without --live and with --live and one Foxglove client subscribed to every
// channel (images at the default 15 Hz), alternated, `--repeats` times each. Prints each run's
// frames/s (summary.json "fps": frames over the pipeline's wall time, the wait for the client
// excluded) and CPU seconds of the whole ademono process (/usr/bin/time: user + system, less
// sensitive to other jobs on the machine than frames/s), their medians, and checks that every
// run's trajectory.tum is the same.
//   node tools/bench_live.js [--repeats 3] [--frames 0:600] [--out DIR] [--live-args "OPTIONS"]
// --live-args: more `ademono run` options for the live runs, e.g. "--live-image-hz 1".
// Needs ADEMONO_CLI (default build/release/bin/ademono) and the npm packages of
// scripts/setup.sh (.deps/foxglove/node_modules).
'use strict';
const c = require('../tests/live/live_common');

const { FoxgloveClient } = c.need('@foxglove/ws-protocol');
const WebSocket = c.need('ws');

function option(name, fallback) {
  const i = process.argv.indexOf(name);
  return i >= 0 ? process.argv[i + 1] : fallback;
}

async function liveRun(out) {
  const extra = option('--live-args', '').split(/\s+/).filter((a) => a);
  const run = c.startLive(out, ['--live-wait-clients', '1'].concat(extra), { timed: true });
  const wsUrl = await c.withTimeout(run.wsUrl, 60000, 'serving');
  const client = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  let messages = 0;
  client.on('advertise', (list) => { for (const ch of list) client.subscribe(ch.id); });
  client.on('message', () => { messages++; });
  client.on('error', () => {});
  const exit = await c.withTimeout(run.exited, 600000, 'the run');
  client.close();
  if (exit.code !== 0) throw new Error('run failed: ' + exit.stderr);
  return { messages, cpu: c.cpuSeconds(exit.stderr) };
}

function median(v) {
  const s = v.slice().sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
}

async function main() {
  process.env.ADEMONO_LIVE_FRAMES = option('--frames', '0:600');
  const repeats = Number(option('--repeats', '3'));
  const root = option('--out', c.tempDir('bench'));
  const fps = { plain: [], live: [] }, cpu = { plain: [], live: [] };
  let trajectory = null, identical = true;
  for (let i = 0; i < repeats; i++) {
    for (const kind of (i % 2 === 0 ? ['plain', 'live'] : ['live', 'plain'])) {
      const out = c.path.join(root, kind + '-' + i);
      const r = kind === 'plain' ? c.runPlain(out, { timed: true }) : await liveRun(out);
      const messages = r.messages || 0;
      cpu[kind].push(r.cpu);
      const summary = JSON.parse(c.fs.readFileSync(c.path.join(out, 'summary.json'), 'utf8'));
      fps[kind].push(summary.fps);
      const t = c.fs.readFileSync(c.path.join(out, 'trajectory.tum'));
      if (trajectory === null) trajectory = t; else identical = identical && t.equals(trajectory);
      console.log(kind, 'run', i, 'fps', summary.fps.toFixed(1), 'cpu_s', r.cpu, 'tracked', summary.tracked,
        kind === 'live' ? 'messages ' + messages + ' live ' + JSON.stringify(summary.live) : '');
    }
  }
  const plain = median(fps.plain), live = median(fps.live);
  console.log(JSON.stringify({ frames: process.env.ADEMONO_LIVE_FRAMES, repeats, fps,
    median_plain: plain, median_live: live, cost_percent: 100 * (plain - live) / plain,
    cpu, median_cpu_plain: median(cpu.plain), median_cpu_live: median(cpu.live),
    cpu_cost_percent: 100 * (median(cpu.live) - median(cpu.plain)) / median(cpu.plain),
    trajectories_identical: identical }, null, 1));
}

main().catch((e) => { console.error(e); process.exit(1); });
