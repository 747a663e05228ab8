// Draws an ademono run report (or a comparison of runs) from the JSON in #report-data.
// 2D plots: uPlot. Map view: regl (WebGL). The C++ side (report/report.cpp) has already aligned
// the trajectories, chosen the thumbnails and subsampled the map; this file only draws.
(function () {
  'use strict';

  const errorBox = document.createElement('div');
  const errorList = [];
  function showError(message) {
    errorList.push(message);
    errorBox.className = 'errors';
    errorBox.textContent = 'The report could not draw everything:\n' + errorList.join('\n');
    document.body.dataset.errors = String(errorList.length);
    if (!errorBox.parentNode) document.body.insertBefore(errorBox, document.body.firstChild);
  }
  window.addEventListener('error', (e) => showError(String(e.message)));

  const COLORS = {
    est: '#e8590c', gt: '#343a40', err: '#c92a2a', scale: '#5f3dc4', mapScale: '#0b7285', inliers: '#1971c2',
    kf: '#1971c2', reloc: '#f08c00', loop: '#9c36b5', lost: 'rgba(224, 49, 49, 0.16)', uninit: 'rgba(134, 142, 150, 0.18)',
  };
  const AXIS_COLORS = ['#d9480f', '#2b8a3e', '#1864ab'];
  const STAGE_COLORS = {
    extraction: '#4dabf7', depth: '#9775fa', detection: '#f783ac', filter: '#ffd43b',
    tracking: '#ff922b', mapping: '#69db7c',
  };
  // Filter labels as filter/visualize.h draws them on the frames.
  const FILTER_SERIES = [
    ['kept', 'kept', '#37b24d'],
    ['removed_enhancement', 'enhancement', '#fab005'],
    ['removed_small_box', 'small box', '#e64980'],
    ['removed_stage1', 'stage 1', '#f03e3e'],
    ['removed_stage2', 'stage 2', '#a61e4d'],
    ['removed_box_vote', 'box vote', '#862e9c'],
    ['removed_distant', 'distant', '#868e96'],
  ];
  const VARIANT_COLORS = ['#e8590c', '#1971c2', '#2b8a3e', '#9c36b5', '#e03131', '#0c8599', '#5c940d', '#d6336c'];

  function el(tag, attrs, ...children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'style') node.style.cssText = v;
      else node.setAttribute(k, v);
    }
    for (const c of children) {
      if (c === null || c === undefined) continue;
      node.appendChild(typeof c === 'string' || typeof c === 'number' ? document.createTextNode(String(c)) : c);
    }
    return node;
  }
  function fmt(v, digits) {
    if (v === null || v === undefined || Number.isNaN(v)) return '–';
    return typeof v === 'number' ? v.toFixed(digits === undefined ? 3 : digits) : String(v);
  }
  function card(value, key) { return el('div', { class: 'card' }, el('div', { class: 'v' }, value), el('div', { class: 'k' }, key)); }
  function panel(title, ...children) { return el('div', { class: 'panel' }, el('h2', {}, title), ...children); }
  function note(text) { return el('div', { class: 'note' }, text); }
  function swatch(color) { return el('span', { class: 'sw', style: 'background:' + color }); }
  function decodeBase64(b64) {
    const bin = atob(b64);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }

  // Plots are created once their container is in the page, at its width, and follow resizes.
  const plots = [];
  function plotWidth(container) { return Math.max(240, container.clientWidth); }
  window.addEventListener('resize', () => {
    for (const p of plots) p.u.setSize({ width: plotWidth(p.container), height: p.height });
  });
  function makePlot(container, height, opts, data) {
    const u = new uPlot(Object.assign({ width: plotWidth(container), height: height }, opts), data, container);
    plots.push({ u: u, container: container, height: height });
    return u;
  }

  // Shades lost / not-yet-initialised frames and marks relocalisations behind a time plot.
  function statePlugin(F, marks) {
    return {
      hooks: {
        drawClear: [(u) => {
          if (!F || !F.t || F.t.length === 0) return;
          const ctx = u.ctx, top = u.bbox.top, h = u.bbox.height;
          const n = F.t.length;
          const half = n > 1 ? (F.t[n - 1] - F.t[0]) / (n - 1) / 2 : 0.5;
          ctx.save();
          for (let i = 0; i < n; i++) {
            if (F.state[i] === 1) continue;
            const x0 = u.valToPos(F.t[i] - half, 'x', true), x1 = u.valToPos(F.t[i] + half, 'x', true);
            ctx.fillStyle = F.state[i] === 2 ? COLORS.lost : COLORS.uninit;
            ctx.fillRect(x0, top, Math.max(1, x1 - x0), h);
          }
          if (marks) {
            ctx.lineWidth = Math.max(1, devicePixelRatio);
            for (let i = 0; i < n; i++) {
              const x = u.valToPos(F.t[i], 'x', true);
              if (F.relocalised[i] === 1) {
                ctx.strokeStyle = COLORS.reloc;
                ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + h); ctx.stroke();
              }
              if (F.loop && F.loop[i] === 1) {
                ctx.strokeStyle = COLORS.loop;
                ctx.lineWidth = 3 * Math.max(1, devicePixelRatio);
                ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + h); ctx.stroke();
                ctx.lineWidth = Math.max(1, devicePixelRatio);
              }
              if (F.keyframe[i] === 1) {
                ctx.strokeStyle = COLORS.kf;
                ctx.beginPath(); ctx.moveTo(x, top + h); ctx.lineTo(x, top + h - 8 * devicePixelRatio); ctx.stroke();
              }
            }
          }
          ctx.restore();
        }],
      },
    };
  }

  const timeAxis = { label: 'time (s)', labelSize: 20, size: 36 };
  function timeOpts(title, yLabel, series, F, marks) {
    return {
      title: title,
      cursor: { sync: { key: 'frames' } },
      scales: { x: { time: false } },
      axes: [timeAxis, { label: yLabel, labelSize: 18, size: 56 }],
      series: [{ label: 't (s)', value: (u, v) => fmt(v, 2) }].concat(series),
      plugins: F ? [statePlugin(F, marks)] : [],
    };
  }

  // Stacked areas (cumulative sums drawn top first, so each band shows one part); the legend
  // shows each part's own value.
  function stackedPlot(container, title, yLabel, t, parts, F, digits, extra) {
    const n = t.length;
    const cum = [];
    const acc = new Array(n).fill(0);
    for (const p of parts) {
      for (let i = 0; i < n; i++) acc[i] += p.values[i] || 0;
      cum.push(acc.slice());
    }
    const series = [], data = [t];
    for (let k = parts.length - 1; k >= 0; k--) {
      const p = parts[k];
      series.push({
        label: p.label, stroke: p.color, fill: p.color, width: 1, points: { show: false },
        value: (u, v, si, i) => (i === null || i === undefined ? '–' : fmt(p.values[i], digits)),
      });
      data.push(cum[k]);
    }
    // Series drawn over the stack, not added to it.
    for (const e of extra || []) {
      series.push({ label: e.label, stroke: e.color, width: 2, dash: [6, 4], points: { show: false },
        value: (u, v) => fmt(v, digits) });
      data.push(e.values);
    }
    const opts = timeOpts(title, yLabel, series, F, false);
    opts.scales.y = { range: (u, min, max) => [0, max > 0 ? max * 1.05 : 1] };
    return makePlot(container, 240, opts, data);
  }

  // A path in the plane of two axes (uPlot's facet mode), drawn point to point in order.
  function pathBuilder(u, seriesIdx, idx0, idx1) {
    const d = u.data[seriesIdx];
    const p = new Path2D();
    for (let i = idx0; i <= idx1; i++) {
      const x = u.valToPos(d[0][i], 'x', true), y = u.valToPos(d[1][i], 'y', true);
      if (i === idx0) p.moveTo(x, y); else p.lineTo(x, y);
    }
    return { stroke: p, fill: null, clip: null, band: null, gaps: null, flags: 0 };
  }
  // The two axes with the largest extent (the ground plane for a camera moving in a room).
  function planeAxes(columnsList) {
    const ext = [0, 0, 0];
    for (let a = 0; a < 3; a++) {
      let lo = Infinity, hi = -Infinity;
      for (const c of columnsList) for (const v of c[a]) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      ext[a] = hi > lo ? hi - lo : 0;
    }
    const order = [0, 1, 2].sort((a, b) => ext[b] - ext[a]);
    return [Math.min(order[0], order[1]), Math.max(order[0], order[1]), order[2]];
  }
  function topViewPlot(container, paths) {
    const [ax, ay] = planeAxes(paths.map((p) => p.xyz));
    const names = ['x', 'y', 'z'];
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (const p of paths) {
      for (const v of p.xyz[ax]) { x0 = Math.min(x0, v); x1 = Math.max(x1, v); }
      for (const v of p.xyz[ay]) { y0 = Math.min(y0, v); y1 = Math.max(y1, v); }
    }
    if (!(x1 > x0)) { x0 -= 0.5; x1 += 0.5; }
    if (!(y1 > y0)) { y0 -= 0.5; y1 += 0.5; }
    // Equal metres per pixel on both axes (the plot area is about width-70 by height-60 px).
    const height = 440, width = plotWidth(container);
    const pw = Math.max(100, width - 70), ph = height - 60;
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    const mpp = Math.max((x1 - x0) / pw, (y1 - y0) / ph) * 1.08;
    const xr = [cx - (mpp * pw) / 2, cx + (mpp * pw) / 2], yr = [cy - (mpp * ph) / 2, cy + (mpp * ph) / 2];
    const series = [{}];
    const data = [null];
    for (const p of paths) {
      series.push({
        label: p.label, stroke: p.color, width: p.width || 2, dash: p.dash,
        facets: [{ scale: 'x', auto: false }, { scale: 'y', auto: false }], paths: pathBuilder,
        points: { show: false },
      });
      data.push([p.xyz[ax], p.xyz[ay]]);
    }
    const opts = {
      mode: 2, title: 'Top view (' + names[ax] + '–' + names[ay] + ' plane, metres)',
      width: width, height: height,
      legend: { live: false },
      cursor: { show: false },
      scales: { x: { time: false, auto: false, range: () => xr }, y: { auto: false, range: () => yr } },
      axes: [{ label: names[ax] + ' (m)', labelSize: 20, size: 36 }, { label: names[ay] + ' (m)', labelSize: 18, size: 56 }],
      series: series,
    };
    const u = new uPlot(opts, data, container);
    plots.push({ u: u, container: container, height: height });
    return u;
  }

  // ---- 3D map view (regl) ----
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
  }
  function lookAt(eye, target, up) {
    let z = [eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]];
    let l = Math.hypot(z[0], z[1], z[2]); z = z.map((v) => v / l);
    let x = [up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]];
    l = Math.hypot(x[0], x[1], x[2]) || 1; x = x.map((v) => v / l);
    const y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]];
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }
  function interleave(cols) {
    const n = cols[0].length, out = new Float32Array(n * 3);
    for (let i = 0; i < n; i++) { out[3 * i] = cols[0][i]; out[3 * i + 1] = cols[1][i]; out[3 * i + 2] = cols[2][i]; }
    return out;
  }
  function mapView(container, map, lines, pointsExtra, viewDir) {
    const canvas = el('canvas', { id: 'map3d' });
    container.appendChild(canvas);
    const dpr = window.devicePixelRatio || 1;
    const regl = createREGL({ canvas: canvas, attributes: { antialias: true, preserveDrawingBuffer: true } });
    const cloud = map && map.count > 0 ? {
      xyz: new Float32Array(decodeBase64(map.xyz_b64).buffer), rgb: decodeBase64(map.rgb_b64),
    } : null;
    // Orbit around the centre of the camera path; "up" is the axis the path spans least.
    const pathCols = lines.map((l) => l.xyz);
    const [, , upAxis] = planeAxes(pathCols);
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const c of pathCols) for (let a = 0; a < 3; a++) for (const v of c[a]) { lo[a] = Math.min(lo[a], v); hi[a] = Math.max(hi[a], v); }
    if (cloud) {
      // The map's 5th-95th percentile box, so a few far outliers do not shrink the view.
      const n = cloud.xyz.length / 3;
      for (let a = 0; a < 3; a++) {
        const v = new Float32Array(n);
        for (let i = 0; i < n; i++) v[i] = cloud.xyz[3 * i + a];
        v.sort();
        lo[a] = Math.min(lo[a], v[Math.floor(0.05 * (n - 1))]);
        hi[a] = Math.max(hi[a], v[Math.ceil(0.95 * (n - 1))]);
      }
    }
    const center = [0, 1, 2].map((a) => (Number.isFinite(lo[a]) ? (lo[a] + hi[a]) / 2 : 0));
    const radius = Math.max(0.5, ...[0, 1, 2].map((a) => (Number.isFinite(lo[a]) ? hi[a] - lo[a] : 0)));
    const up = [0, 0, 0]; up[upAxis] = upAxis === 1 ? -1 : 1;  // y is down in camera-style worlds
    // Sparse maps get bigger dots, dense ones smaller so they do not turn into a blob.
    const pointSize = !cloud ? 1 : cloud.xyz.length / 3 < 5000 ? 4 : cloud.xyz.length / 3 < 30000 ? 3 : 2;
    const cam = { yaw: 0.8, pitch: 0.5, dist: radius * 1.2, target: center.slice() };
    if (viewDir) {
      // Start behind the cameras, looking where they looked, a little from above.
      const a1 = (upAxis + 1) % 3, a2 = (upAxis + 2) % 3;
      cam.yaw = Math.atan2(-viewDir[a2], -viewDir[a1]);
      cam.pitch = Math.max(-1.2, Math.min(1.2, Math.asin(Math.max(-1, Math.min(1, -viewDir[upAxis] * up[upAxis]))) + 0.45));
    }

    const vert = 'precision mediump float; attribute vec3 position; attribute vec3 color; uniform mat4 proj, view; uniform float size; varying vec3 vColor;' +
      'void main() { vColor = color; gl_Position = proj * view * vec4(position, 1.0); gl_PointSize = size; }';
    const frag = 'precision mediump float; varying vec3 vColor; void main() { gl_FragColor = vec4(vColor, 1.0); }';
    const uniforms = { proj: regl.prop('proj'), view: regl.prop('view'), size: regl.prop('size') };
    const drawPoints = cloud ? regl({
      vert: vert, frag: frag, uniforms: uniforms, primitive: 'points', count: cloud.xyz.length / 3,
      attributes: { position: regl.buffer(cloud.xyz), color: { buffer: regl.buffer({ data: cloud.rgb, type: 'uint8' }), normalized: true, size: 3 } },
    }) : null;
    function hexColor(h) { return [1, 3, 5].map((i) => parseInt(h.substr(i, 2), 16) / 255); }
    const lineVert = 'precision mediump float; attribute vec3 position; uniform mat4 proj, view; uniform float size;' +
      'void main() { gl_Position = proj * view * vec4(position, 1.0); gl_PointSize = size; }';
    const lineFrag = 'precision mediump float; uniform vec3 color; void main() { gl_FragColor = vec4(color, 1.0); }';
    const drawLines = lines.filter((l) => l.xyz[0].length > 1).map((l) => regl({
      vert: lineVert, frag: lineFrag, primitive: 'line strip', count: l.xyz[0].length,
      attributes: { position: regl.buffer(interleave(l.xyz)) },
      uniforms: Object.assign({ color: hexColor(l.color) }, uniforms),
    }));
    const drawMarks = (pointsExtra || []).filter((p) => p.xyz[0].length > 0).map((p) => regl({
      vert: lineVert, frag: lineFrag, primitive: 'points', count: p.xyz[0].length,
      depth: { enable: false },  // poses stay visible over the map, later marks (keyframes) on top
      attributes: { position: regl.buffer(interleave(p.xyz)) },
      uniforms: Object.assign({ color: hexColor(p.color) }, uniforms),
    }));

    function render() {
      const w = canvas.clientWidth * dpr, h = canvas.clientHeight * dpr;
      if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
      regl.poll();
      regl.clear({ color: [0.086, 0.102, 0.133, 1], depth: 1 });
      // Eye on a sphere around the target, in a frame whose "up" is upAxis.
      const a1 = (upAxis + 1) % 3, a2 = (upAxis + 2) % 3;
      const eye = cam.target.slice();
      eye[a1] += cam.dist * Math.cos(cam.pitch) * Math.cos(cam.yaw);
      eye[a2] += cam.dist * Math.cos(cam.pitch) * Math.sin(cam.yaw);
      eye[upAxis] += up[upAxis] * cam.dist * Math.sin(cam.pitch);
      const props = { proj: perspective(Math.PI / 4, w / Math.max(1, h), radius * 0.01, radius * 20), view: lookAt(eye, cam.target, up) };
      if (drawPoints) drawPoints(Object.assign({ size: pointSize * dpr }, props));
      for (const d of drawMarks) d(Object.assign({ size: 4 * dpr }, props));
      for (const d of drawLines) d(Object.assign({ size: 1 }, props));
    }
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey }; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const s = cam.dist / canvas.clientHeight;
        const a1 = (upAxis + 1) % 3, a2 = (upAxis + 2) % 3;
        // Screen right/up mapped onto the ground plane and the up axis.
        cam.target[a1] += s * dx * Math.sin(cam.yaw);
        cam.target[a2] -= s * dx * Math.cos(cam.yaw);
        cam.target[upAxis] += up[upAxis] * s * dy;
      } else {
        cam.yaw -= dx * 0.01;
        cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + dy * 0.01));
      }
      render();
    });
    canvas.addEventListener('wheel', (e) => { e.preventDefault(); cam.dist *= Math.exp(e.deltaY * 0.001); render(); }, { passive: false });
    window.addEventListener('resize', render);
    render();
  }

  // ---- a single run ----
  function renderRun(D) {
    const app = document.getElementById('app');
    const S = D.summary, F = D.frames, T = D.traj;
    app.appendChild(el('h1', {}, 'ademono run report: ' + D.title));
    app.appendChild(el('div', { class: 'sub' }, 'dataset ' + (S.dataset || '?') + ' · depth ' + (S.depth || '?') + ' · detector ' + (S.detector || '?') +
      ' · filters ' + Object.entries(S.filters || {}).map(([k, v]) => k + (v ? ' on' : ' off')).join(', ') + ' · seed ' + fmt(S.seed, 0) +
      (S.deterministic ? ' · deterministic' : '')));
    const acc = S.accuracy || {};
    const cards = el('div', { class: 'cards' },
      card(fmt(S.tracked, 0) + ' / ' + fmt(S.frames, 0), 'frames tracked'), card(fmt(S.lost, 0), 'lost'),
      card(fmt(S.keyframes, 0), 'keyframes'), card(fmt(S.map_points, 0), 'map points'), card(fmt(S.fps, 1), 'frames / s'));
    if (S.accuracy) {
      cards.appendChild(card(fmt(acc.ate_se3_rmse_m, 4) + ' m', 'ATE se3 RMSE'));
      cards.appendChild(card(fmt(acc.ate_sim3_rmse_m, 4) + ' m', 'ATE sim3 RMSE (scale ' + fmt(acc.sim3_scale, 3) + ')'));
      cards.appendChild(card(fmt(acc.rpe_30_frames_trans_rmse_m, 4) + ' m', 'RPE 30 frames'));
    }
    if (S.metric_scale) {
      cards.appendChild(card('± ' + fmt(100 * S.metric_scale.sigma, 1) + ' %',
        'metric scale (' + (S.metric_scale.source === 'ground' ? 'the road' : 'the network') + '), its bias aside'));
    }
    app.appendChild(cards);

    // Trajectory.
    const trajPanel = panel('Trajectory');
    app.appendChild(trajPanel);
    if (D.alignment_note) trajPanel.appendChild(note(D.alignment_note));
    else trajPanel.appendChild(el('div', { class: 'hint' }, 'Estimate aligned to the ground truth with ' + D.alignment +
      (T.scale !== undefined ? ' (scale ' + fmt(T.scale, 4) + ')' : '') + '; ATE RMSE over ' + T.err.length + ' poses: ' + fmt(T.ate.rmse, 4) + ' m.' +
      (D.alignment_reason ? ' Aligned with ' + D.alignment + ', not se3: ' + D.alignment_reason + '.' : '')));
    // Top view on the left, each axis over time on the right.
    const top = el('div', { id: 'plot-top' });
    const axesBox = el('div', { id: 'plot-axes' });
    trajPanel.appendChild(el('div', { class: 'grid2' }, top, axesBox));
    const paths = [];
    if (T.gt) paths.push({ label: 'ground truth', xyz: T.gt, color: COLORS.gt, width: 2 });
    paths.push({ label: 'estimate', xyz: T.est, color: COLORS.est, width: 2 });
    topViewPlot(top, paths);
    for (let a = 0; a < 3; a++) {
      const name = 'xyz'[a];
      const box = el('div', {});
      axesBox.appendChild(box);
      const series = [{ label: 'estimate ' + name, stroke: COLORS.est, width: 1.5, value: (u, v) => fmt(v, 3) }];
      let data;
      if (T.gt) {
        // One x axis for both: the estimate's stamps; ground truth sits on the matched ones.
        const joined = uPlot.join([[T.t, T.est[a]], [T.gt_t, T.gt[a]]]);
        data = joined;
        series.unshift({ label: 'ground truth ' + name, stroke: COLORS.gt, width: 1.5, spanGaps: true, value: (u, v) => fmt(v, 3) });
        data = [joined[0], joined[2], joined[1]];
      } else {
        data = [T.t, T.est[a]];
      }
      const opts = timeOpts(name + ' over time', name + ' (m)', series, F, false);
      opts.legend = { show: false };  // same two series as the top view's legend
      makePlot(box, 150, opts, data);
    }

    // Error over time.
    const errPanel = panel('Error over time');
    app.appendChild(errPanel);
    if (T.err) {
      const box = el('div', { id: 'plot-error' });
      errPanel.appendChild(box);
      makePlot(box, 220, timeOpts('Absolute position error after ' + D.alignment + ' alignment', 'error (m)',
        [{ label: 'error', stroke: COLORS.err, width: 1.5, fill: 'rgba(201, 42, 42, 0.08)', value: (u, v) => fmt(v, 4) }], F, false), [T.gt_t, T.err]);
    } else {
      errPanel.appendChild(note('No error to plot: ' + (D.alignment_note || 'no ground truth.')));
    }
    if (F.depth_scale) {
      const box = el('div', { id: 'plot-scale' });
      errPanel.appendChild(box);
      makePlot(box, 180, timeOpts('Depth scale factor per frame', 'scale',
        [{ label: 'depth scale', stroke: COLORS.scale, width: 1.5, spanGaps: false, value: (u, v) => fmt(v, 4) }], F, false), [F.t, F.depth_scale]);
    } else {
      errPanel.appendChild(el('div', { class: 'hint' }, 'No per-frame depth scale factor in this run.'));
    }
    if (F.scale_sigma) {
      // How well the run pinned its scale source down as it went (not the source's own bias).
      const box = el('div', { id: 'plot-scale-sigma' });
      errPanel.appendChild(box);
      const opts = timeOpts("The metric scale's relative standard error, as each frame left it", '%',
        [{ label: 'scale sigma', stroke: COLORS.scale, width: 1.5, spanGaps: false, value: (u, v) => fmt(v, 2) }], F, false);
      opts.scales.y = { range: (u, min, max) => [0, max > 0 ? max * 1.1 : 1] };
      makePlot(box, 150, opts, [F.t, F.scale_sigma.map((v) => (v === null ? null : 100 * v))]);
    }
    if (F.map_scale) {
      // Where the dataset has depth images: the map's own scale per keyframe (1 = metric). Its
      // spread is the map's scale drift.
      const box = el('div', { id: 'plot-map-scale' });
      errPanel.appendChild(box);
      makePlot(box, 180, timeOpts("The map's scale against the dataset's depth, per keyframe", 'sensor / map',
        [{ label: 'map scale', stroke: COLORS.mapScale, width: 1.5, spanGaps: true,
           points: { show: true, size: 6, fill: COLORS.mapScale }, value: (u, v) => fmt(v, 4) }], F, false), [F.t, F.map_scale]);
    }

    // Timeline: states, relocalisations, keyframes, inliers.
    const tlPanel = panel('Tracking timeline');
    app.appendChild(tlPanel);
    tlPanel.appendChild(el('div', { class: 'legend-row' },
      el('span', {}, swatch(COLORS.lost), 'lost'), el('span', {}, swatch(COLORS.uninit), 'not initialised'),
      el('span', {}, swatch(COLORS.reloc), 'relocalised'), el('span', {}, swatch(COLORS.kf), 'keyframe (tick)'),
      el('span', {}, swatch(COLORS.loop), 'loop closed'),
      el('span', {}, fmt(F.keyframe.reduce((a, b) => a + b, 0), 0) + ' keyframes, ' + fmt(F.relocalised.reduce((a, b) => a + b, 0), 0) + ' relocalisations, ' +
        fmt((F.loop || []).reduce((a, b) => a + b, 0), 0) + ' loops, ' +
        fmt(F.state.filter((s) => s === 2).length, 0) + ' lost frames, ' +
        fmt((F.weak || []).filter((w) => w === 1).length, 0) + ' weak poses on few static points, ' +
        fmt((F.weak || []).filter((w) => w === 2).length, 0) + ' on the motion model alone, ' +
        fmt((F.weak || []).filter((w) => w === 3).length, 0) + ' on the last frame\'s depths (off the map)')));
    const tl = el('div', { id: 'plot-timeline' });
    tlPanel.appendChild(tl);
    // Negative counts mean "not recorded": such series are left out.
    const counts = [
      [F.keypoints, { label: 'keypoints', stroke: '#adb5bd', width: 1 }],
      [F.kept, { label: 'kept by the filters', stroke: '#37b24d', width: 1 }],
      [F.with_depth, { label: 'with depth', stroke: '#9775fa', width: 1 }],
      [F.inliers, { label: 'inliers', stroke: COLORS.inliers, width: 1.5 }],
      [F.static_points || [], { label: 'static points the pose rests on', stroke: '#0b7285', width: 1 }],
      [F.geometric_dynamic || [], { label: 'matches judged moving (geometry)', stroke: '#e03131', width: 1 }],
    ].filter(([v]) => v.length > 0 && v.some((x) => x >= 0));
    makePlot(tl, 200, timeOpts('Features and inliers per frame', 'points', counts.map(([, s]) => s), F, true),
      [F.t].concat(counts.map(([v]) => v)));

    // Timing and critical path.
    const timePanel = panel('Time per frame');
    app.appendChild(timePanel);
    // The main thread's stages stacked in pipeline order; the prefetch worker (depth + detection
    // of the next frame, in parallel) as a dashed line: a frame costs the higher of the two.
    // Which stage ran where comes with the critical path (summary.json says it per stage); the
    // per-thread CPU and wait columns are not stages and are left out of the stack.
    const C0 = D.critical_path;
    const mainStages = C0 ? C0.stages.filter((s) => s.branch === 'main').map((s) => s.stage) : ['extraction', 'filter', 'tracking', 'mapping'];
    const workerStages = C0 ? C0.stages.filter((s) => s.branch !== 'main').map((s) => s.stage) : ['depth', 'detection'];
    const notStages = ['prefetch_wait', 'tracking_thread_cpu', 'prefetch_thread_cpu'];
    const stages = Object.keys(F.ms);
    if (stages.length > 0) {
      const box = el('div', { id: 'plot-timing' });
      timePanel.appendChild(box);
      const stacked = mainStages.filter((s) => F.ms[s]).concat(stages.filter((s) => !mainStages.includes(s) && !workerStages.includes(s) && !notStages.includes(s)));
      const worker = F.t.map((_, i) => workerStages.reduce((a, s) => a + (F.ms[s] ? F.ms[s][i] : 0), 0));
      stackedPlot(box, 'Main-thread time per frame by module (stacked), prefetch worker dashed', 'ms', F.t,
        stacked.map((s) => ({ label: s, values: F.ms[s], color: STAGE_COLORS[s] || '#adb5bd' })), F, 2,
        workerStages.some((s) => F.ms[s]) ? [{ label: 'worker: ' + workerStages.join(' + '), values: worker, color: '#7048e8' }] : []);
    } else {
      timePanel.appendChild(note('No per-frame timing in this run.'));
    }
    const C = D.critical_path;
    if (C) {
      const maxMs = Math.max(1e-9, ...C.stages.map((s) => s.median_ms));
      const rows = C.stages.map((s) => el('tr', { class: s.stage === C.dominant_stage ? 'crit' : '' },
        el('td', {}, s.stage), el('td', {}, s.branch === 'main' ? 'main thread' : 'prefetch worker'), el('td', {}, fmt(s.median_ms, 2)),
        el('td', { style: 'text-align:left' }, el('span', { class: 'bar', style: 'width:' + Math.round(160 * s.median_ms / maxMs) + 'px;background:' + (STAGE_COLORS[s.stage] || '#adb5bd') }))));
      const bound = C.from_medians ? ' is the longer branch (from the per-stage medians in summary.json); median ' :
        ' bounds ' + (C.critical_branch === 'main' ? C.main_bound_frames : C.frames - C.main_bound_frames) + ' of ' + C.frames + ' frames; median ';
      timePanel.appendChild(el('p', {}, 'Critical path: the ' + (C.critical_branch === 'main' ? 'main thread (' + C.stages.filter((s) => s.branch === 'main').map((s) => s.stage).join(' → ') + ')' : 'prefetch worker (' + C.stages.filter((s) => s.branch !== 'main').map((s) => s.stage).join(' + ') + ')') +
        bound +
        fmt(C.main_median_ms, 1) + ' ms on the main thread vs ' + fmt(C.worker_median_ms, 1) + ' ms on the worker, which runs one frame ahead. ' +
        'Dominant stage: ', el('b', {}, C.dominant_stage), ' (median ' + fmt(C.dominant_median_ms, 1) + ' ms).'));
      timePanel.appendChild(el('table', {}, el('tr', {}, el('th', {}, 'stage'), el('th', {}, 'runs on'), el('th', {}, 'median ms'), el('th', {}, '')), ...rows));
    }

    // Filters.
    const filtPanel = panel('Feature filters per frame');
    app.appendChild(filtPanel);
    const fparts = FILTER_SERIES.filter(([k]) => F.filter[k]).map(([k, label, color]) => ({ label: label, values: F.filter[k], color: color }));
    if (fparts.length > 0) {
      const box = el('div', { id: 'plot-filter' });
      filtPanel.appendChild(box);
      stackedPlot(box, 'Keypoints per frame by filter label (stacked)', 'keypoints', F.t, fparts, F, 0);
    } else {
      filtPanel.appendChild(note('No per-frame filter counts in this run.'));
    }

    // 3D map.
    const mapPanel = panel('Map and camera path (3D)');
    app.appendChild(mapPanel);
    const M = D.map;
    mapPanel.appendChild(el('div', { class: 'hint' },
      (M.count > 0 ? M.count + ' map points' + (M.stride > 1 ? ' (every ' + M.stride + 'th of ' + M.total + ', subsampled for the view)' : '') : (M.note || 'no map points')) +
      '. Drag to turn, wheel to zoom, right-drag or shift-drag to pan. ',
      swatch(COLORS.est), 'estimate ', T.gt ? swatch('#ced4da') : null, T.gt ? 'ground truth ' : null, swatch('#4dabf7'), 'keyframes'));
    const lines = [];
    if (T.gt) lines.push({ xyz: T.gt, color: '#ced4da' });
    lines.push({ xyz: T.est, color: COLORS.est });
    // Poses as dots as well: WebGL draws lines 1 px wide only.
    const marks = [];
    if (T.gt) marks.push({ xyz: T.gt, color: '#ced4da' });
    marks.push({ xyz: T.est, color: COLORS.est }, { xyz: T.kf, color: '#4dabf7' });
    mapView(mapPanel, M, lines, marks, T.view_dir);

    // Thumbnails.
    const thPanel = panel('Frames that matter');
    app.appendChild(thPanel);
    if (D.thumbs_note) thPanel.appendChild(note(D.thumbs_note));
    if (D.thumbs.length > 0) {
      thPanel.appendChild(el('div', { class: 'legend-row' }, ...FILTER_SERIES.map(([, label, color]) => el('span', {}, swatch(color), label))));
      thPanel.appendChild(el('div', { class: 'thumbs' }, ...D.thumbs.map((th) => el('figure', {},
        el('img', { src: 'data:image/jpeg;base64,' + th.jpeg_b64, alt: 'frame ' + th.frame }),
        el('figcaption', {}, 'frame ' + th.frame + ': ' + th.reason)))));
    }
  }

  // ---- several runs ----
  function renderComparison(D) {
    const app = document.getElementById('app');
    const V = D.variants;
    app.appendChild(el('h1', {}, 'ademono comparison: ' + V.length + ' runs'));
    app.appendChild(el('div', { class: 'sub' }, 'dataset ' + (V[0].summary.dataset || '?') + ' · each estimate aligned to its ground truth with ' + D.alignment));
    const filterKeys = FILTER_SERIES.map(([k]) => k).filter((k) => V.some((v) => v.summary.filter_counts && v.summary.filter_counts[k] !== undefined));
    const filterLabel = Object.fromEntries(FILTER_SERIES.map(([k, label]) => [k, k === 'kept' ? 'kept' : '− ' + label]));
    const head = el('tr', {}, el('th', {}, 'run'), el('th', {}, 'filters'), el('th', {}, 'tracked'), el('th', {}, 'lost'), el('th', {}, 'keyframes'),
      el('th', {}, 'map points'), el('th', {}, 'ATE ' + D.alignment + ' (m)'), el('th', {}, 'ATE se3'), el('th', {}, 'ATE sim3'),
      ...filterKeys.map((k) => el('th', {}, filterLabel[k])));
    const filterFlags = (f) => (f ? [['enhancement', 'E'], ['dynamic_removal', 'D'], ['distant', 'F']].map(([k, c]) => (f[k] ? c : '·')).join('') : '?');
    const bestAte = Math.min(...V.map((v) => (v.ate_rmse_m === undefined ? Infinity : v.ate_rmse_m)));
    const rows = V.map((v, i) => {
      const s = v.summary, a = s.accuracy || {}, fc = s.filter_counts || {};
      return el('tr', {}, el('td', {}, swatch(VARIANT_COLORS[i % VARIANT_COLORS.length]), v.name), el('td', { style: 'font-family:monospace' }, filterFlags(s.filters)),
        el('td', {}, fmt(s.tracked, 0) + '/' + fmt(s.frames, 0)),
        el('td', {}, fmt(s.lost, 0)), el('td', {}, fmt(s.keyframes, 0)), el('td', {}, fmt(s.map_points, 0)),
        el('td', { class: v.ate_rmse_m === bestAte ? 'crit' : '' }, fmt(v.ate_rmse_m, 4)), el('td', {}, fmt(a.ate_se3_rmse_m, 4)), el('td', {}, fmt(a.ate_sim3_rmse_m, 4)),
        ...filterKeys.map((k) => el('td', {}, fmt(fc[k], 0))));
    });
    app.appendChild(panel('Accuracy and filter totals', el('div', { class: 'scroll' }, el('table', {}, head, ...rows)),
      el('div', { class: 'hint' }, 'filters: E enhancement, D dynamic removal, F distant filter (· off); filter columns are keypoints over the whole run.')));

    const trajPanel = panel('Trajectories');
    app.appendChild(trajPanel);
    const paths = [];
    const withGt = V.find((v) => v.traj.gt);
    if (withGt) paths.push({ label: 'ground truth', xyz: withGt.traj.gt, color: COLORS.gt, width: 2.5 });
    V.forEach((v, i) => paths.push({ label: v.name, xyz: v.traj.est, color: VARIANT_COLORS[i % VARIANT_COLORS.length], width: 1.5 }));
    const top = el('div', { id: 'plot-top' });
    trajPanel.appendChild(top);
    topViewPlot(top, paths);

    const errVariants = V.map((v, i) => [v, i]).filter(([v]) => v.traj.err);
    if (errVariants.length > 0) {
      const box = el('div', { id: 'plot-error' });
      trajPanel.appendChild(box);
      const joined = uPlot.join(errVariants.map(([v]) => [v.traj.gt_t, v.traj.err]));
      makePlot(box, 240, timeOpts('Absolute position error over time', 'error (m)', errVariants.map(([v, i]) => ({
        label: v.name, stroke: VARIANT_COLORS[i % VARIANT_COLORS.length], width: 1.5, spanGaps: true, value: (u, x) => fmt(x, 4),
      })), null, false), joined);
    }
    const keptVariants = V.map((v, i) => [v, i]).filter(([v]) => v.frames.filter && v.frames.filter.kept);
    if (keptVariants.length > 0) {
      const box = el('div', { id: 'plot-filter' });
      app.appendChild(panel('Kept keypoints per frame', box));
      const joined = uPlot.join(keptVariants.map(([v]) => [v.frames.t, v.frames.filter.kept]));
      makePlot(box, 220, timeOpts('Keypoints kept by the filters', 'keypoints', keptVariants.map(([v, i]) => ({
        label: v.name, stroke: VARIANT_COLORS[i % VARIANT_COLORS.length], width: 1.2, spanGaps: true,
      })), null, false), joined);
    }
  }

  try {
    const D = JSON.parse(document.getElementById('report-data').textContent);
    if (D.kind === 'comparison') renderComparison(D); else renderRun(D);
    // Where each plot and the 3D view landed (page pixels), for the browser test's pixel checks;
    // measured once the page has loaded and laid out.
    const recordLayout = () => {
      const layout = {};
      for (const node of document.querySelectorAll('[id^="plot-"], #map3d')) {
        const r = node.getBoundingClientRect();
        layout[node.id] = [Math.round(r.left + scrollX), Math.round(r.top + scrollY), Math.round(r.width), Math.round(r.height)];
      }
      const app = document.getElementById('app').getBoundingClientRect();
      layout.page = [0, 0, Math.round(app.right), Math.ceil(app.bottom + scrollY)];
      document.body.dataset.layout = JSON.stringify(layout);
      document.body.dataset.ready = '1';
    };
    window.addEventListener('load', () => setTimeout(recordLayout, 100));
  } catch (e) {
    showError(String(e && e.stack ? e.stack : e));
    console.error(e);
  }
})();
