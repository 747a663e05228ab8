#!/usr/bin/env node
// Acceptance test of the live view with a real Foxglove client (npm @foxglove/ws-protocol over
// npm ws): `ademono run --live` on 200 frames of seq-a (sensor depth) waits for this client,
// which subscribes to every advertised channel and checks that
// - every message parses and validates against its channel's advertised JSON schema (ajv);
// - the final /trajectory is trajectory.tum pose for pose, and every live /camera/pose is a
//   frame of trajectory.tum (same timestamp, within 5 cm of its refined pose);
// - the last /map point cloud has map.ply's point count, the last /scene keyframes.tum's
//   keyframes, the final /ademono/run status the run's counts;
// - images are JPEG, frames arrive in order, summary.json counts the live view's messages.
//   node tests/live/live_client_test.js [--port N] [--realtime]   (default: any free port)
// --realtime: the same with `--realtime --realtime-speed 2` (frames the run has no time for are
// dropped; the checks hold for the frames it took).
'use strict';
const c = require('./live_common');

const { FoxgloveClient } = c.need('@foxglove/ws-protocol');
const WebSocket = c.need('ws');
const Ajv = c.need('ajv');

const REQUIRED = {
  '/tf': 'foxglove.FrameTransform',
  '/camera/pose': 'foxglove.PoseInFrame',
  '/trajectory': 'foxglove.PosesInFrame',
  '/map': 'foxglove.PointCloud',
  '/camera/image': 'foxglove.CompressedImage',
  '/camera/annotations': 'foxglove.ImageAnnotations',
  '/scene': 'foxglove.SceneUpdate',
  '/ademono/frame': 'ademono.FrameStats',
  '/ademono/run': 'ademono.RunStatus',
};

async function main() {
  const t = new c.Checks();
  const out = c.tempDir('client');
  const realtime = process.argv.includes('--realtime') ? ['--realtime', '--realtime-speed', '2'] : [];
  const run = c.startLive(out, ['--live-wait-clients', '1', '--live-linger', '20'].concat(realtime));
  const wsUrl = await c.withTimeout(run.wsUrl, 60000, 'the run to start serving');

  const ajv = new Ajv({ strict: false, allErrors: false });
  const channels = new Map();  // channel id -> {topic, schemaName, validate}
  const bySubscription = new Map();
  const received = {};  // topic -> [messages]
  let serverInfo = null, invalid = 0, firstInvalid = null, statusErrors = [];
  const decoder = new TextDecoder();

  const client = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const done = new Promise((resolve, reject) => {
    client.on('error', (e) => reject(e));
    client.on('serverInfo', (info) => { serverInfo = info; });
    client.on('status', (s) => { if (s.level >= 2) statusErrors.push(s.message); });
    client.on('advertise', (list) => {
      for (const ch of list) {
        channels.set(ch.id, { topic: ch.topic, schemaName: ch.schemaName, encoding: ch.encoding,
          validate: ajv.compile(JSON.parse(ch.schema)) });
        bySubscription.set(client.subscribe(ch.id), ch.id);
      }
    });
    client.on('message', ({ subscriptionId, data }) => {
      const ch = channels.get(bySubscription.get(subscriptionId));
      const message = JSON.parse(decoder.decode(data));
      if (!ch.validate(message)) {
        invalid++;
        if (!firstInvalid) firstInvalid = ch.topic + ': ' + ajv.errorsText(ch.validate.errors);
      }
      (received[ch.topic] = received[ch.topic] || []).push(message);
      if (ch.topic === '/ademono/run' && message.state === 'finished') {
        client.close();
        resolve();
      }
    });
    client.on('close', () => resolve());
  });
  await c.withTimeout(done, 240000, 'the run to finish');
  const exit = await c.withTimeout(run.exited, 60000, 'the run to exit');
  t.check(exit.code === 0, 'run exit code ' + exit.code + ': ' + exit.stderr);

  t.check(serverInfo && serverInfo.name === 'ademono', 'serverInfo names the server');
  for (const [topic, schema] of Object.entries(REQUIRED)) {
    const ch = [...channels.values()].find((x) => x.topic === topic);
    t.check(ch && ch.schemaName === schema && ch.encoding === 'json', topic + ' advertised as ' + schema);
    t.check((received[topic] || []).length > 0, topic + ': messages received');
  }
  const total = Object.values(received).reduce((n, l) => n + l.length, 0);
  t.check(invalid === 0, invalid + ' of ' + total + ' messages invalid; first: ' + firstInvalid);
  t.check(statusErrors.length === 0, 'server errors: ' + statusErrors.join('; '));

  // The final trajectory is trajectory.tum, pose for pose (9 decimals there).
  const tum = c.readTum(c.path.join(out, 'trajectory.tum'));
  const trajectories = received['/trajectory'] || [];
  const last = trajectories[trajectories.length - 1];
  t.check(last && last.poses.length === tum.length,
    'final /trajectory has ' + (last && last.poses.length) + ' poses, trajectory.tum ' + tum.length);
  let worst = 0;
  if (last) {
    last.poses.forEach((p, i) => {
      if (!tum[i]) return;
      const v = [p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y,
        p.orientation.z, p.orientation.w];
      v.forEach((x, k) => { worst = Math.max(worst, Math.abs(x - tum[i][k + 1])); });
    });
  }
  t.check(worst < 1e-8, 'final /trajectory differs from trajectory.tum by ' + worst);

  // Live poses: frames of trajectory.tum, at their refined place within 5 cm.
  const byStamp = new Map(tum.map((r) => [Math.round(r[0] * 1e6), r]));
  const poses = received['/camera/pose'] || [];
  let unmatched = 0, far = 0;
  for (const m of poses) {
    const stamp = Math.round((m.timestamp.sec + m.timestamp.nsec * 1e-9) * 1e6);
    const r = byStamp.get(stamp);
    if (!r) { unmatched++; continue; }
    const p = m.pose.position;
    if (Math.hypot(p.x - r[1], p.y - r[2], p.z - r[3]) > 0.05) far++;
  }
  t.check(poses.length >= tum.length / 2, poses.length + ' live poses for ' + tum.length + ' tracked frames');
  t.check(unmatched === 0, unmatched + ' live poses at no frame of trajectory.tum');
  t.check(far === 0, far + ' live poses more than 5 cm from trajectory.tum');
  const tf = received['/tf'] || [];
  t.check(tf.every((m) => m.parent_frame_id === 'world' && m.child_frame_id === 'camera'), '/tf is world -> camera');

  // The last point cloud is the final map.
  const maps = received['/map'] || [];
  const cloud = maps[maps.length - 1];
  const points = cloud ? Buffer.from(cloud.data, 'base64').length / cloud.point_stride : -1;
  const plyPoints = c.plyVertexCount(c.path.join(out, 'map.ply'));
  t.check(points === plyPoints, 'last /map has ' + points + ' points, map.ply ' + plyPoints);
  t.check(maps.length < tum.length / 2, maps.length + ' map clouds: sent when the map changed, not every frame');

  const scenes = received['/scene'] || [];
  const scene = scenes[scenes.length - 1];
  const keyframes = scene ? scene.entities.find((e) => e.id === 'keyframes').cubes.length : -1;
  const keyTum = c.readTum(c.path.join(out, 'keyframes.tum')).length;
  t.check(keyframes === keyTum, 'last /scene has ' + keyframes + ' keyframes, keyframes.tum ' + keyTum);

  const status = (received['/ademono/run'] || []).slice(-1)[0];
  const summary = JSON.parse(c.fs.readFileSync(c.path.join(out, 'summary.json'), 'utf8'));
  t.check(status && status.state === 'finished' && status.tracked === summary.tracked &&
    status.frames === summary.frames && status.map_points === summary.map_points,
  'finished status carries the run counts');

  const images = received['/camera/image'] || [];
  t.check(images.every((m) => m.format === 'jpeg' && Buffer.from(m.data, 'base64').subarray(0, 2).equals(Buffer.from([0xff, 0xd8]))),
    'images are JPEG');
  const frames = (received['/ademono/frame'] || []).map((m) => m.frame);
  t.check(frames.every((f, i) => i === 0 || f > frames[i - 1]), 'frame stats in order');
  t.check(frames.length >= summary.frames / 2, frames.length + ' frame stats for ' + summary.frames + ' frames');
  const annotations = received['/camera/annotations'] || [];
  t.check(annotations.some((m) => m.points.some((p) => p.type === 1 && p.points.length > 50)),
    'annotations carry the keypoints');

  t.check(summary.live && summary.live.clients === 1 && summary.live.messages_sent > 0 &&
    Number.isInteger(summary.live.messages_dropped) && Number.isInteger(summary.live.frames_skipped),
  'summary.json counts the live view: ' + JSON.stringify(summary.live));
  console.log('received', Object.fromEntries(Object.entries(received).map(([k, v]) => [k, v.length])),
    'summary.live', JSON.stringify(summary.live));
  c.fs.rmSync(out, { recursive: true, force: true });
  t.finish();
}

main().catch((e) => { console.error(e); process.exit(1); });
