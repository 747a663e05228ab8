// The live page of `ademono run --live` (src/ademono/live): a Foxglove WebSocket client
// (subprotocol foxglove.websocket.v1, JSON encoding) that subscribes to every channel the server
// advertises and draws the path and the map in 3D (regl) and the per-frame numbers (uPlot).
// body.dataset: frames (messages of /ademono/frame seen), state (the run's), ready = "1" once the
// run has finished and its final map and plots are drawn, errors = "1" on a failure; layout: the
// panels' rectangles (tests/live/live_browser_test.py).
(function () {
  'use strict';
  const body = document.body;
  const $ = (id) => document.getElementById(id);
  function fail(message) {
    body.dataset.errors = '1';
    $('status').textContent = message;
    console.error(message);
  }
  window.addEventListener('error', (e) => { body.dataset.errors = '1'; $('status').textContent = String(e.message); });

  function decodeBase64(text) {
    const bin = atob(text), out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }
  const fmt = (v, d) => (v === null || v === undefined ? '–' : Number(v).toFixed(d));

  // ---- state ----
  const live = { path: [], refined: null, cloud: null, keyframes: [], loops: [], camera: null, status: null };
  const series = { frame: [], inliers: [], kept: [], keypoints: [], tracking: [], filter: [], mapping: [], extraction: [], scale: [] };
  const MAX_POINTS = 20000;  // per plot series: enough for a long run, bounded for the browser
  let frames = 0, lastFrame = null, finished = false, dirty3d = true, dirtyPlots = true;

  // ---- 3D view (regl) ----
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
  }
  function lookAt(eye, target, up) {
    let z = [eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]];
    let l = Math.hypot(z[0], z[1], z[2]) || 1; z = z.map((v) => v / l);
    let x = [up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]];
    l = Math.hypot(x[0], x[1], x[2]) || 1; x = x.map((v) => v / l);
    const y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]];
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }
  const canvas = $('view3d');
  const dpr = window.devicePixelRatio || 1;
  // No preserveDrawingBuffer: the page redraws often, and a preserved buffer makes SwiftShader
  // read the pixels back for every frame (a console warning per redraw).
  const regl = createREGL({ canvas: canvas, attributes: { antialias: true, preserveDrawingBuffer: false } });
  const vert = 'precision mediump float; attribute vec3 position; attribute vec3 color; uniform mat4 proj, view; uniform float size; varying vec3 vColor;' +
    'void main() { vColor = color; gl_Position = proj * view * vec4(position, 1.0); gl_PointSize = size; }';
  const frag = 'precision mediump float; varying vec3 vColor; void main() { gl_FragColor = vec4(vColor, 1.0); }';
  const flatVert = 'precision mediump float; attribute vec3 position; uniform mat4 proj, view; uniform float size;' +
    'void main() { gl_Position = proj * view * vec4(position, 1.0); gl_PointSize = size; }';
  const flatFrag = 'precision mediump float; uniform vec3 color; void main() { gl_FragColor = vec4(color, 1.0); }';
  const cloudXyz = regl.buffer({ usage: 'dynamic', type: 'float', length: 12 });
  const cloudRgb = regl.buffer({ usage: 'dynamic', type: 'uint8', length: 3 });
  const drawCloud = regl({
    vert: vert, frag: frag, primitive: 'points', count: regl.prop('count'),
    attributes: { position: cloudXyz, color: { buffer: cloudRgb, normalized: true, size: 3 } },
    uniforms: { proj: regl.prop('proj'), view: regl.prop('view'), size: regl.prop('size') },
  });
  const flat = (primitive, depth) => regl({
    vert: flatVert, frag: flatFrag, primitive: primitive, count: regl.prop('count'),
    depth: { enable: depth },
    attributes: { position: regl.prop('position') },
    uniforms: { proj: regl.prop('proj'), view: regl.prop('view'), size: regl.prop('size'), color: regl.prop('color') },
  });
  const drawStrip = flat('line strip', true), drawLinePairs = flat('lines', true), drawMarks = flat('points', false);
  const pathBuffer = regl.buffer({ usage: 'dynamic', type: 'float', length: 12 });
  const keyBuffer = regl.buffer({ usage: 'dynamic', type: 'float', length: 12 });
  const loopBuffer = regl.buffer({ usage: 'dynamic', type: 'float', length: 12 });
  const camBuffer = regl.buffer({ usage: 'dynamic', type: 'float', length: 12 });
  // Orbit camera; "up" is -y (camera-style worlds: y points down at the first frame).
  const up = [0, -1, 0];
  const cam = { yaw: -1.9, pitch: 0.6, dist: 3, target: [0, 0, 1], auto: true };

  function pathPositions() {
    if (live.refined && live.refined.length >= live.path.length) return live.refined;
    // The refined trajectory so far, then the live poses since it was sent.
    const refined = live.refined || [];
    return refined.concat(live.path.slice(refined.length));
  }
  function fitView(path) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const p of path) for (let a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
    if (live.cloud && live.cloud.count > 20) {
      // The map's 5th-95th percentile box, so a few far points do not shrink the view.
      const n = live.cloud.count, xyz = live.cloud.xyz;
      for (let a = 0; a < 3; a++) {
        const v = new Float32Array(n);
        for (let i = 0; i < n; i++) v[i] = xyz[3 * i + a];
        v.sort();
        lo[a] = Math.min(lo[a], v[Math.floor(0.05 * (n - 1))]);
        hi[a] = Math.max(hi[a], v[Math.ceil(0.95 * (n - 1))]);
      }
    }
    if (!Number.isFinite(lo[0])) return;
    cam.target = [0, 1, 2].map((a) => (lo[a] + hi[a]) / 2);
    cam.dist = 1.3 * Math.max(0.5, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  }
  function render3d() {
    const w = Math.round(canvas.clientWidth * dpr), h = Math.round(canvas.clientHeight * dpr);
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    regl.poll();
    regl.clear({ color: [0.086, 0.102, 0.133, 1], depth: 1 });
    const path = pathPositions();
    if (cam.auto) fitView(path);
    const eye = [cam.target[0] + cam.dist * Math.cos(cam.pitch) * Math.cos(cam.yaw),
      cam.target[1] - cam.dist * Math.sin(cam.pitch),
      cam.target[2] + cam.dist * Math.cos(cam.pitch) * Math.sin(cam.yaw)];
    const props = { proj: perspective(Math.PI / 4, w / Math.max(1, h), cam.dist * 0.01, cam.dist * 30), view: lookAt(eye, cam.target, up) };
    if (live.cloud && live.cloud.count > 0) {
      const size = live.cloud.count < 5000 ? 4 : live.cloud.count < 30000 ? 3 : 2;
      drawCloud(Object.assign({ count: live.cloud.count, size: size * dpr }, props));
    }
    if (path.length > 1) {
      pathBuffer(path.flat());
      drawStrip(Object.assign({ position: pathBuffer, count: path.length, size: 1, color: [0.91, 0.35, 0.05] }, props));
    }
    if (live.loops.length > 0) {
      loopBuffer(live.loops.flat());
      drawLinePairs(Object.assign({ position: loopBuffer, count: live.loops.length, size: 1, color: [0.79, 0.16, 0.16] }, props));
    }
    if (live.keyframes.length > 0) {
      keyBuffer(live.keyframes.flat());
      drawMarks(Object.assign({ position: keyBuffer, count: live.keyframes.length, size: 5 * dpr, color: [0.3, 0.67, 0.97] }, props));
    }
    if (live.camera) {
      camBuffer(live.camera);
      drawMarks(Object.assign({ position: camBuffer, count: 1, size: 11 * dpr, color: [1, 1, 1] }, props));
    }
  }
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey }; cam.auto = false; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const s = cam.dist / canvas.clientHeight;
      cam.target[0] += s * dx * Math.sin(cam.yaw);
      cam.target[2] -= s * dx * Math.cos(cam.yaw);
      cam.target[1] -= s * dy;
    } else {
      cam.yaw -= dx * 0.01;
      cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + dy * 0.01));
    }
    dirty3d = true;
  });
  canvas.addEventListener('wheel', (e) => { e.preventDefault(); cam.auto = false; cam.dist *= Math.exp(e.deltaY * 0.001); dirty3d = true; }, { passive: false });

  // ---- plots (uPlot) ----
  function plot(id, labels, colors, yLabel) {
    const host = $(id);
    const opts = {
      width: Math.max(200, host.clientWidth), height: 200, legend: { live: false },
      scales: { x: { time: false } },
      axes: [{ label: 'frame' }, { label: yLabel }],
      series: [{}].concat(labels.map((l, i) => ({ label: l, stroke: colors[i], width: 1.5, spanGaps: false }))),
    };
    return new uPlot(opts, [[]].concat(labels.map(() => [])), host);
  }
  const plots = {
    points: plot('plot-points', ['keypoints', 'kept', 'inliers'], ['#adb5bd', '#37b24d', '#1971c2'], 'points'),
    ms: plot('plot-ms', ['extraction', 'filter', 'tracking', 'local mapping'], ['#868e96', '#fab005', '#ff922b', '#69db7c'], 'ms'),
    scale: plot('plot-scale', ['depth scale'], ['#5f3dc4'], 'factor'),
  };
  let scaleSeen = false;
  function drawPlots() {
    const s = series;
    plots.points.setData([s.frame, s.keypoints, s.kept, s.inliers]);
    plots.ms.setData([s.frame, s.extraction, s.filter, s.tracking, s.mapping]);
    plots.scale.setData([s.frame, s.scale]);
  }

  // ---- camera image and annotations ----
  const image = $('image'), overlay = $('overlay');
  let annotations = null, imageSize = [640, 480];
  function drawOverlay() {
    const w = overlay.clientWidth, h = overlay.clientHeight;
    if (w === 0 || h === 0) return;
    if (overlay.width !== w * dpr) { overlay.width = w * dpr; overlay.height = h * dpr; }
    const ctx = overlay.getContext('2d');
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, overlay.width, overlay.height);
    if (!annotations) return;
    ctx.scale(overlay.width / imageSize[0], overlay.height / imageSize[1]);
    const css = (c) => 'rgba(' + Math.round(255 * c.r) + ',' + Math.round(255 * c.g) + ',' + Math.round(255 * c.b) + ',' + c.a + ')';
    for (const p of annotations.points) {
      ctx.strokeStyle = css(p.outline_color);
      ctx.fillStyle = css(p.fill_color);
      if (p.type === 1) {
        for (const q of p.points) ctx.fillRect(q.x - 1.5, q.y - 1.5, 3, 3);
      } else if (p.points.length > 1) {
        ctx.lineWidth = p.thickness;
        ctx.beginPath();
        ctx.moveTo(p.points[0].x, p.points[0].y);
        for (const q of p.points.slice(1)) ctx.lineTo(q.x, q.y);
        if (p.type === 2) ctx.closePath();
        ctx.stroke();
      }
    }
    ctx.font = '12px sans-serif';
    for (const t of annotations.texts) {
      ctx.fillStyle = css(t.background_color);
      const width = ctx.measureText(t.text).width;
      ctx.fillRect(t.position.x, t.position.y - 13, width + 4, 15);
      ctx.fillStyle = css(t.text_color);
      ctx.fillText(t.text, t.position.x + 2, t.position.y - 2);
    }
  }
  image.addEventListener('load', () => { imageSize = [image.naturalWidth, image.naturalHeight]; drawOverlay(); });

  // ---- messages ----
  function push(name, value) {
    const a = series[name];
    a.push(value);
    if (a.length > MAX_POINTS) a.shift();
  }
  const handlers = {
    '/camera/pose': (m) => {
      const p = m.pose.position;
      live.camera = [p.x, p.y, p.z];
      live.path.push([p.x, p.y, p.z]);
      dirty3d = true;
    },
    '/trajectory': (m) => {
      live.refined = m.poses.map((p) => [p.position.x, p.position.y, p.position.z]);
      dirty3d = true;
    },
    '/map': (m) => {
      const bytes = decodeBase64(m.data), stride = m.point_stride;
      const field = (name) => m.fields.find((f) => f.name === name);
      const fx = field('x').offset, fy = field('y').offset, fz = field('z').offset;
      const fr = field('red').offset, fg = field('green').offset, fb = field('blue').offset;
      const count = stride > 0 ? Math.floor(bytes.length / stride) : 0;
      const view = new DataView(bytes.buffer), xyz = new Float32Array(3 * count), rgb = new Uint8Array(3 * count);
      for (let i = 0; i < count; i++) {
        const o = i * stride;
        xyz[3 * i] = view.getFloat32(o + fx, true); xyz[3 * i + 1] = view.getFloat32(o + fy, true); xyz[3 * i + 2] = view.getFloat32(o + fz, true);
        rgb[3 * i] = bytes[o + fr]; rgb[3 * i + 1] = bytes[o + fg]; rgb[3 * i + 2] = bytes[o + fb];
      }
      live.cloud = { count: count, xyz: xyz };
      if (count > 0) { cloudXyz(xyz); cloudRgb(rgb); }
      dirty3d = true;
    },
    '/scene': (m) => {
      for (const e of m.entities) {
        if (e.id === 'keyframes') live.keyframes = e.cubes.map((c) => [c.pose.position.x, c.pose.position.y, c.pose.position.z]);
        if (e.id === 'loops') live.loops = e.lines.length ? e.lines[0].points.map((p) => [p.x, p.y, p.z]) : [];
      }
      dirty3d = true;
    },
    '/camera/image': (m) => { image.src = 'data:image/' + m.format + ';base64,' + m.data; },
    '/camera/annotations': (m) => { annotations = m; drawOverlay(); },
    '/ademono/frame': (m) => {
      frames++;
      lastFrame = m;
      push('frame', m.frame); push('keypoints', m.keypoints); push('kept', m.kept); push('inliers', m.inliers);
      push('extraction', m.ms.extraction); push('filter', m.ms.filter); push('tracking', m.ms.tracking); push('mapping', m.ms.mapping);
      push('scale', m.depth_scale);
      if (m.depth_scale !== null && !scaleSeen) { scaleSeen = true; $('scale-note').hidden = true; }
      dirtyPlots = true;
    },
    '/ademono/run': (m) => {
      live.status = m;
      if (m.state === 'finished') finished = true;
    },
  };

  function showStatus() {
    const parts = [];
    if (live.status) parts.push('run ' + live.status.state);
    if (lastFrame) {
      parts.push('frame ' + lastFrame.frame + ' (' + lastFrame.state + (lastFrame.keyframe ? ', keyframe' : '') + ')');
      parts.push('inliers ' + lastFrame.inliers);
      if (lastFrame.depth_scale !== null) parts.push('depth scale ' + fmt(lastFrame.depth_scale, 3));
      if (lastFrame.scale_sigma !== null && lastFrame.scale_sigma !== undefined)
        parts.push('metric scale ± ' + fmt(100 * lastFrame.scale_sigma, 1) + ' %');
    }
    if (live.cloud) parts.push(live.cloud.count + ' map points');
    parts.push(live.keyframes.length + ' keyframes');
    if (finished && live.status) parts.push('tracked ' + live.status.tracked + '/' + live.status.frames);
    $('status').textContent = parts.join(' · ');
    body.dataset.frames = String(frames);
    body.dataset.state = live.status ? live.status.state : '';
  }

  function layout() {
    const out = {};
    for (const id of ['view3d', 'camera', 'plot-points', 'plot-ms', 'plot-scale']) {
      const r = $(id).getBoundingClientRect();
      out[id] = [Math.round(r.left + window.scrollX), Math.round(r.top + window.scrollY), Math.round(r.width), Math.round(r.height)];
    }
    return JSON.stringify(out);
  }

  let finishedDrawn = false;
  function frameLoop() {
    try {
      if (dirty3d) { render3d(); dirty3d = false; }
      if (dirtyPlots) { drawPlots(); dirtyPlots = false; }
      showStatus();
      if (finished && !finishedDrawn && !dirty3d && !dirtyPlots) {
        finishedDrawn = true;
        body.dataset.layout = layout();
        body.dataset.ready = '1';
      }
    } catch (e) {
      fail('drawing failed: ' + e.message);
      return;
    }
    setTimeout(() => requestAnimationFrame(frameLoop), 100);  // ~10 redraws a second at most
  }

  // ---- the Foxglove WebSocket protocol ----
  const ws = new WebSocket('ws://' + location.host + '/', ['foxglove.websocket.v1']);
  ws.binaryType = 'arraybuffer';
  const topics = {};  // subscription id (= channel id) -> topic
  const decoder = new TextDecoder();
  ws.onopen = () => { $('conn').textContent = 'connected'; $('conn').className = 'badge open'; };
  ws.onclose = () => {
    $('conn').textContent = finished ? 'run finished' : 'disconnected';
    $('conn').className = 'badge' + (finished ? '' : ' closed');
  };
  ws.onmessage = (event) => {
    if (typeof event.data === 'string') {
      const m = JSON.parse(event.data);
      if (m.op === 'advertise') {
        const subscriptions = [];
        for (const c of m.channels) {
          if (c.encoding !== 'json' || topics[c.id]) continue;
          topics[c.id] = c.topic;
          subscriptions.push({ id: c.id, channelId: c.id });
        }
        ws.send(JSON.stringify({ op: 'subscribe', subscriptions: subscriptions }));
      } else if (m.op === 'status' && m.level >= 2) {
        fail('server: ' + m.message);
      }
      return;
    }
    const view = new DataView(event.data);
    if (view.getUint8(0) !== 1) return;  // only message data is expected
    const topic = topics[view.getUint32(1, true)];
    const handler = handlers[topic];
    if (handler) handler(JSON.parse(decoder.decode(new Uint8Array(event.data, 13))));
  };
  requestAnimationFrame(frameLoop);
})();
