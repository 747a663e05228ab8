#!/usr/bin/env node
// Determinism with viewers: `ademono run --live` with two clients attached (one reading every
// channel, one that subscribes to everything and then stops reading) writes trajectory.tum,
// keyframes.tum and map.ply byte for byte as a run without --live.
//   node tests/live/live_determinism_test.js [--port N] [--baseline RUN_DIR]
'use strict';
const c = require('./live_common');

const { FoxgloveClient } = c.need('@foxglove/ws-protocol');
const WebSocket = c.need('ws');

function attach(wsUrl, { stall }) {
  const ws = new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const state = { messages: 0, finished: false, ws };
  const runChannel = new Map();
  client.on('advertise', (list) => {
    for (const ch of list) runChannel.set(client.subscribe(ch.id), ch.topic);
    if (stall) setTimeout(() => ws._socket.pause(), 300);
  });
  client.on('message', ({ subscriptionId, data }) => {
    state.messages++;
    if (runChannel.get(subscriptionId) === '/ademono/run' &&
        JSON.parse(new TextDecoder().decode(data)).state === 'finished') {
      state.finished = true;
      client.close();
    }
  });
  client.on('error', () => {});
  return state;
}

async function main() {
  const t = new c.Checks();
  const args = process.argv.slice(2);
  const b = args.indexOf('--baseline');
  const baseline = b >= 0 ? args[b + 1] : c.runPlain(c.tempDir('baseline'));
  const out = c.tempDir('two-clients');
  const run = c.startLive(out, ['--live-wait-clients', '2', '--live-linger', '20']);
  const wsUrl = await c.withTimeout(run.wsUrl, 60000, 'the run to start serving');
  const reader = attach(wsUrl, { stall: false });
  const staller = attach(wsUrl, { stall: true });
  // The stalled client would hold the server's linger (at most 20 s): it leaves once the run
  // has finished.
  const deadline = Date.now() + 240000;
  while (!reader.finished && Date.now() < deadline) await new Promise((r) => setTimeout(r, 50));
  staller.ws.terminate();
  const exit = await c.withTimeout(run.exited, 60000, 'the run to exit');
  t.check(exit.code === 0, 'run exit code ' + exit.code + ': ' + exit.stderr);
  t.check(reader.finished && reader.messages > 100, 'the reading client saw the run (' + reader.messages + ' messages)');
  for (const f of ['trajectory.tum', 'keyframes.tum', 'map.ply']) {
    t.check(c.sameFile(c.path.join(out, f), c.path.join(baseline, f)), f + ' identical to the run without --live');
  }
  const summary = JSON.parse(c.fs.readFileSync(c.path.join(out, 'summary.json'), 'utf8'));
  t.check(summary.live && summary.live.clients === 2, 'two clients: ' + JSON.stringify(summary.live));
  console.log('summary.live', JSON.stringify(summary.live));
  c.fs.rmSync(out, { recursive: true, force: true });
  t.finish();
}

main().catch((e) => { console.error(e); process.exit(1); });
