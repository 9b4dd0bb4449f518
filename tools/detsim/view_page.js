// The replay viewer's script: inlined into every page `detsim view` writes (tools/detsim/cmd_view.cpp
// packs the data it reads; docs/VIEWER.md describes both). Plain ES2017 on three.js r111 (Debian's
// libjs-three, inlined before it), no other dependency, nothing fetched: the page works offline.
(function () {
  'use strict';
  const started = performance.now();
  const meta = JSON.parse(document.getElementById('detsim-meta').textContent);
  const chunkText = document.getElementById('detsim-chunks').textContent.split('\n').filter((s) => s.length > 0);
  const sides = meta.records.length;
  const unit = meta.players * meta.input_size;
  const LENGTH = 1 / meta.length_scale;
  const UNIT = 1 / meta.unit_scale;

  // ---- page layout ----
  const style = document.createElement('style');
  style.textContent = `
    html, body { margin: 0; height: 100%; overflow: hidden; background: #1c2129; color: #e6e9ef;
      font: 13px/1.4 system-ui, sans-serif; }
    #view { position: absolute; inset: 0; }
    #panel { position: absolute; top: 8px; left: 8px; max-width: 440px; background: rgba(20,24,31,.86);
      padding: 8px 10px; border-radius: 6px; }
    #panel h1 { font-size: 14px; margin: 0 0 4px; font-weight: 600; }
    #panel .files { color: #aab2c0; word-break: break-all; }
    #panel code { font: 12px ui-monospace, monospace; }
    #panel table { border-collapse: collapse; margin-top: 4px; }
    #panel td, #panel th { padding: 0 8px 0 0; text-align: left; font: 12px ui-monospace, monospace; }
    #panel th { color: #aab2c0; font-weight: normal; }
    .bad { color: #ff7b72; } .ok { color: #7ee787; } .dim { color: #8b93a1; }
    #bar { position: absolute; left: 0; right: 0; bottom: 0; display: flex; gap: 8px; align-items: center;
      padding: 8px 10px; background: rgba(20,24,31,.9); }
    #bar input[type=range] { flex: 1; }
    #bar button, #bar select { background: #2d333d; color: #e6e9ef; border: 1px solid #444c56;
      border-radius: 4px; padding: 3px 10px; font: inherit; }
    #frame { font: 12px ui-monospace, monospace; min-width: 150px; text-align: right; }
    #legend { position: absolute; top: 8px; right: 8px; background: rgba(20,24,31,.86); padding: 6px 10px;
      border-radius: 6px; }
    #legend span { display: inline-block; width: 10px; height: 10px; margin-right: 6px; border-radius: 2px; }
  `;
  document.head.appendChild(style);
  const el = (tag, attrs, text) => {
    const e = document.createElement(tag);
    Object.entries(attrs || {}).forEach(([k, v]) => e.setAttribute(k, v));
    if (text !== undefined) e.textContent = text;
    return e;
  };
  const view = el('div', { id: 'view' });
  const panel = el('div', { id: 'panel' });
  const bar = el('div', { id: 'bar' });
  const legend = el('div', { id: 'legend' });
  document.body.append(view, panel, legend, bar);
  const play = el('button', { id: 'play', title: 'play / pause (space)' }, '▶');
  const slider = el('input', { id: 'slider', type: 'range', min: meta.first, max: meta.last, value: meta.first });
  const speed = el('select', { id: 'speed', title: 'playback speed' });
  [0.25, 0.5, 1, 2, 4, 8, 16, 64].forEach((s) => {
    const o = el('option', { value: s }, s + '×');
    if (s === 1) o.selected = true;
    speed.append(o);
  });
  const frameLabel = el('span', { id: 'frame' });
  bar.append(play, slider, frameLabel, speed);
  if (meta.first_divergent_frame !== null) {
    const jump = el('button', { id: 'divergence', title: 'go to the first divergent frame' },
      'divergence: ' + meta.first_divergent_frame);
    jump.onclick = () => show(Math.max(meta.first, Math.min(meta.last, meta.first_divergent_frame)));
    bar.append(jump);
  }
  const swatch = (color, text) => {
    const d = el('div');
    const s = el('span');
    s.style.background = color;
    d.append(s, document.createTextNode(text));
    return d;
  };
  legend.append(swatch('#8a8f98', 'static'), swatch('#4c8be0', 'kinematic'), swatch('#e0a040', 'dynamic'));
  if (sides === 2) legend.append(swatch('#ff4040', 'differs (A)'), swatch('#ff9a3c', 'side B where it differs'));

  // ---- three.js scene ----
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.append(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1c2129);
  const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 5000);
  const target = new THREE.Vector3().fromArray(meta.camera.target);
  const distance = Math.max(3, meta.camera.radius * 1.7);
  camera.position.copy(target).add(new THREE.Vector3(0.55, 0.6, 1).normalize().multiplyScalar(distance));
  camera.lookAt(target);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(target);
  controls.update();
  scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x303540, 0.75));
  const sun = new THREE.DirectionalLight(0xffffff, 0.7);
  sun.position.set(0.4, 1, 0.6);
  scene.add(sun);

  const hue = (id) => new THREE.Color().setHSL(((id * 0.618034) % 1) * 0.25 + 0.04, 0.75, 0.55);
  const colorOf = (body) => body.type === 'static' ? new THREE.Color(0x8a8f98)
    : body.type === 'kinematic' ? new THREE.Color(0x4c8be0) : hue(body.id);
  const vec = (a) => new THREE.Vector3(a[0], a[1], a[2]);

  // A sphere painted in octants, so that its turning shows.
  function ballGeometry(radius, color) {
    const g = new THREE.SphereBufferGeometry(radius, 24, 16);
    const p = g.attributes.position;
    const colors = new Float32Array(p.count * 3);
    const dark = color.clone().multiplyScalar(0.55);
    for (let i = 0; i < p.count; i++) {
      const c = (p.getX(i) * p.getY(i) * p.getZ(i) >= 0) ? color : dark;
      colors.set([c.r, c.g, c.b], i * 3);
    }
    g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    return g;
  }

  // An outline (sim/shape_outline.hpp) in body space as a three.js object.
  function outlineObject(o, color, material) {
    const group = new THREE.Group();
    if (o.parts) {
      o.parts.forEach((p) => group.add(outlineObject(p, color, material)));
      return group;
    }
    if (o.half_space) {
      const n = vec(o.normal).normalize();
      const plane = new THREE.Mesh(new THREE.PlaneBufferGeometry(400, 400), material);
      plane.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
      plane.position.copy(vec(o.points[0]));
      group.add(plane);
      const grid = new THREE.GridHelper(400, 400, 0x3a414c, 0x2c323b);
      grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), n);
      grid.position.copy(vec(o.points[0])).addScaledVector(n, 0.002);
      group.add(grid);
      return group;
    }
    if (o.triangles && o.triangles.length) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(o.triangles, 3));
      g.computeVertexNormals();
      group.add(new THREE.Mesh(g, material));
      return group;
    }
    const points = o.points.map(vec);
    if (points.length === 0) return group;
    if (o.radius > 0 && points.length === 1) {
      const m = new THREE.Mesh(ballGeometry(o.radius, color), material.userData.painted || material);
      m.position.copy(points[0]);
      group.add(m);
      return group;
    }
    if (o.radius > 0 && points.length === 2) {
      const axis = points[1].clone().sub(points[0]);
      const length = axis.length();
      const body = new THREE.Mesh(new THREE.CylinderBufferGeometry(o.radius, o.radius, length, 20), material);
      body.position.copy(points[0]).add(points[1]).multiplyScalar(0.5);
      if (length > 0) body.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), axis.normalize());
      group.add(body);
      points.forEach((p) => {
        const end = new THREE.Mesh(new THREE.SphereBufferGeometry(o.radius, 20, 12), material);
        end.position.copy(p);
        group.add(end);
      });
      return group;
    }
    try {
      group.add(new THREE.Mesh(new THREE.ConvexBufferGeometry(points), material));
    } catch (e) {
      group.add(new THREE.Points(new THREE.BufferGeometry().setFromPoints(points),
        new THREE.PointsMaterial({ color: color, size: 0.05 })));
    }
    return group;
  }

  const red = new THREE.MeshLambertMaterial({ color: 0xff4040, emissive: 0x400000 });
  const ghost = new THREE.MeshBasicMaterial({ color: 0xff9a3c, wireframe: true, transparent: true, opacity: 0.8 });
  const objects = [];  // [side][body index] -> { object, normal }
  for (let s = 0; s < sides; s++) {
    objects.push(meta.bodies.map((b) => {
      const color = colorOf(b);
      let material;
      if (s === 1) {
        material = ghost;
      } else {
        // Static solids are see-through where the scene has particles (a tank's fluid, a cloth
        // behind a wall).
        const seeThrough = b.type === 'static' && meta.groups.length > 0 && !b.outline.half_space;
        material = new THREE.MeshLambertMaterial({ color: color, flatShading: b.type !== 'static',
          transparent: seeThrough, opacity: seeThrough ? 0.35 : 1, depthWrite: !seeThrough });
        material.userData.painted = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors });
      }
      const object = outlineObject(b.outline, color, material);
      object.visible = false;
      scene.add(object);
      return { object: object, material: material, red: false, half_space: !!b.outline.half_space };
    }));
  }
  const particleObjects = [];
  for (let s = 0; s < sides; s++) {
    particleObjects.push(meta.groups.map((g, k) => {
      const geometry = new THREE.BufferGeometry();
      const points = new THREE.Points(geometry, new THREE.PointsMaterial({
        color: s === 1 ? 0xff9a3c : new THREE.Color().setHSL(0.6 + 0.07 * k, 0.85, 0.45),
        size: Math.max(0.06, 2 * g.radius), sizeAttenuation: true }));
      points.visible = false;
      points.frustumCulled = false;
      scene.add(points);
      return points;
    }));
  }
  function setRed(entry, on) {
    if (entry.red === on) return;
    entry.red = on;
    entry.object.traverse((m) => {
      if (!m.isMesh) return;
      if (on) { m.userData.material = m.material; m.material = red; } else if (m.userData.material) m.material = m.userData.material;
    });
  }

  // ---- the data: chunks of frames, each inflated when first needed ----
  class Reader {
    constructor(bytes) { this.b = bytes; this.p = 0; }
    u() {
      let r = 0, m = 1, b;
      do { b = this.b[this.p++]; r += (b & 127) * m; m *= 128; } while (b & 128);
      return r;
    }
    s() { const v = this.u(); return v % 2 ? -(v + 1) / 2 : v / 2; }
    hex() {
      let s = '';
      for (let i = 7; i >= 0; i--) s += this.b[this.p + i].toString(16).padStart(2, '0');
      this.p += 8;
      return s;
    }
    byte() { return this.b[this.p++]; }
    take(n) { const out = this.b.subarray(this.p, this.p + n); this.p += n; return out; }
  }
  // Values stored as second differences, written into out[i * stride + offset].
  function integrate(r, count, out, stride, offset, scale) {
    let v = 0, d = 0;
    for (let i = 0; i < count; i++) { d += r.s(); v += d; out[i * stride + offset] = v * scale; }
  }
  async function inflate(text) {
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  function decode(bytes, first) {
    const r = new Reader(bytes);
    const n = r.u();
    const chunk = { first: first, n: n, hash: [], stored: [], recorded: [], inputs: null, bodies: [], groups: [] };
    for (let s = 0; s < sides; s++) { chunk.hash.push([]); chunk.stored.push([]); chunk.recorded.push([]); }
    for (let i = 0; i < n; i++) {
      for (let s = 0; s < sides; s++) {
        chunk.hash[s].push(r.hex());
        const flags = r.byte();
        chunk.stored[s].push(!!(flags & 1));
        chunk.recorded[s].push(flags & 2 ? r.hex() : null);
      }
    }
    const inputs = r.take(n * (unit + 1)).slice();
    for (let i = 1; i < n; i++)
      for (let k = 0; k <= unit; k++) inputs[i * (unit + 1) + k] ^= inputs[(i - 1) * (unit + 1) + k];
    chunk.inputs = inputs;
    for (let s = 0; s < sides; s++) {
      const bodies = [];
      for (let count = r.u(); count > 0; count--) {
        const seg = { index: r.u(), start: r.u(), count: r.u() };
        seg.pose = new Float32Array(seg.count * 7);
        for (let c = 0; c < 7; c++) integrate(r, seg.count, seg.pose, 7, c, c < 3 ? LENGTH : c < 6 ? UNIT : 1);
        seg.differs = new Uint8Array(seg.count);
        for (let runs = r.u(); runs > 0; runs--) {
          const at = r.u();
          seg.differs.fill(1, at, at + r.u());
        }
        bodies.push(seg);
      }
      const groups = [];
      for (let count = r.u(); count > 0; count--) {
        const seg = { index: r.u(), start: r.u(), count: r.u() };
        seg.particles = r.u();
        const width = seg.particles * 3;
        seg.points = new Float32Array(seg.count * width);
        for (let c = 0; c < width; c++) integrate(r, seg.count, seg.points, width, c, LENGTH);
        groups.push(seg);
      }
      chunk.bodies.push(bodies);
      chunk.groups.push(groups);
    }
    return chunk;
  }
  const cache = new Map();  // chunk number -> Promise of a decoded chunk
  function chunk(k) {
    if (!cache.has(k)) {
      if (cache.size >= 12) cache.delete(cache.keys().next().value);
      cache.set(k, inflate(chunkText[k]).then((bytes) => decode(bytes, meta.first + k * meta.chunk_frames)));
    }
    return cache.get(k);
  }
  const chunkOf = (frame) => Math.floor((frame - meta.first) / meta.chunk_frames);

  // ---- showing a frame ----
  let current = meta.first;
  let shown = null;  // the decoded chunk of `current`
  function place(c, frame) {
    const i = frame - c.first;
    for (let s = 0; s < sides; s++) {
      objects[s].forEach((o) => { o.object.visible = false; });
      particleObjects[s].forEach((p) => { p.visible = false; });
      c.bodies[s].forEach((seg) => {
        if (i < seg.start || i >= seg.start + seg.count) return;
        const entry = objects[s][seg.index];
        const k = (i - seg.start) * 7;
        const p = seg.pose;
        const differs = seg.differs[i - seg.start] === 1;
        entry.object.position.set(p[k], p[k + 1], p[k + 2]);
        // The quaternion's smallest three, and which component was left out (positive).
        const q = [0, 0, 0, 0];
        const m = p[k + 6];
        let sum = 0;
        for (let c = 0, j = 3; c < 4; c++) {
          if (c === m) continue;
          q[c] = p[k + j++];
          sum += q[c] * q[c];
        }
        q[m] = Math.sqrt(Math.max(0, 1 - sum));
        entry.object.quaternion.set(q[0], q[1], q[2], q[3]).normalize();
        entry.object.visible = s === 0 || differs || sides === 1;
        if (s === 0 && sides === 2 && !entry.half_space) setRed(entry, differs);
      });
      c.groups[s].forEach((seg) => {
        if (i < seg.start || i >= seg.start + seg.count) return;
        const points = particleObjects[s][seg.index];
        const width = seg.particles * 3;
        points.geometry.setAttribute('position', new THREE.BufferAttribute(
          seg.points.subarray((i - seg.start) * width, (i - seg.start + 1) * width), 3));
        points.geometry.attributes.position.needsUpdate = true;
        points.visible = true;
      });
    }
  }
  const escapeHtml = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
  function describeInputs(c, frame) {
    if (frame === 0 || unit === 0) return '<div class="dim">no inputs at frame 0</div>';
    const row = c.inputs.subarray((frame - c.first) * (unit + 1), (frame - c.first + 1) * (unit + 1));
    const gone = row[0];
    let html = '<table><tr><th>player</th>' + (meta.player_inputs ? '<th>buttons</th><th>stick x</th><th>stick z</th>' : '<th>input bytes</th>') + '</tr>';
    for (let p = 0; p < meta.players; p++) {
      const b = row.subarray(1 + p * meta.input_size, 1 + (p + 1) * meta.input_size);
      const away = (gone >> p) & 1 ? ' <span class="bad">(gone)</span>' : '';
      if (meta.player_inputs) {
        const buttons = [(b[0] & 1) ? 'jump' : '', (b[0] & 2) ? 'dash' : ''].filter((x) => x).join(' ') || '·';
        const sx = b[1] > 127 ? b[1] - 256 : b[1];
        const sz = b[2] > 127 ? b[2] - 256 : b[2];
        html += `<tr><td>${p}${away}</td><td>${buttons}</td><td>${sx}</td><td>${sz}</td></tr>`;
      } else {
        html += `<tr><td>${p}${away}</td><td>${Array.from(b, (x) => x.toString(16).padStart(2, '0')).join('')}</td></tr>`;
      }
    }
    return html + '</table>';
  }
  function describe(c, frame) {
    const i = frame - c.first;
    const t = (frame * meta.dt).toFixed(2);
    const who = meta.players === 0 ? '' : ` · ${meta.players} player${meta.players === 1 ? '' : 's'}`;
    let html = `<h1>${escapeHtml(meta.scenario)} · seed ${meta.seed}${who}</h1>`;
    html += `<div class="files">${meta.records.map((r, s) => (sides === 2 ? 'ABCD'[s] + ': ' : '') + escapeHtml(r.path) + ' <span class="dim">(' + escapeHtml(r.kind) + ')</span>').join('<br>')}</div>`;
    html += `<div>frame <b>${frame}</b> of ${meta.last} · t = ${t} s</div>`;
    for (let s = 0; s < sides; s++) {
      const label = sides === 2 ? 'ABCD'[s] + ' ' : '';
      const stored = c.stored[s][i] ? ' <span class="dim">(its stored state)</span>' : '';
      html += `<div>${label}hash <code id="hash-${s}">${c.hash[s][i]}</code>${stored}`;
      if (c.recorded[s][i]) html += ` <span class="bad">recorded ${c.recorded[s][i]}: this machine differs</span>`;
      html += '</div>';
    }
    if (meta.first_divergent_frame !== null) {
      const diverged = frame >= meta.first_divergent_frame;
      html += `<div class="${diverged ? 'bad' : 'ok'}">${meta.outcome === 'inputs_differ' ? 'inputs differ' : 'diverged'} at frame ${meta.first_divergent_frame}${diverged ? '' : ' (not yet)'}</div>`;
    } else if (sides === 2) {
      html += '<div class="ok">the records agree</div>';
    }
    meta.notes.forEach((n) => { html += `<div class="dim">${escapeHtml(n)}</div>`; });
    panel.innerHTML = html + describeInputs(c, frame);
    frameLabel.textContent = `${frame} / ${meta.last}  ${t} s`;
    slider.value = frame;
  }
  let pending = 0;
  // Shows `frame` (clamped); resolves once it is drawn.
  async function show(frame) {
    frame = Math.max(meta.first, Math.min(meta.last, Math.round(frame)));
    const ticket = ++pending;
    const k = chunkOf(frame);
    const c = await chunk(k);
    if (ticket !== pending) return;  // a later request won
    if (k + 1 < chunkText.length && frame - c.first > meta.chunk_frames / 2) chunk(k + 1);  // read ahead
    current = frame;
    shown = c;
    place(c, frame);
    describe(c, frame);
    render();
    writeProbe();
  }
  // "#size=WxH" in the URL draws at that size whatever the window's (for screenshots and tests).
  const fixedSize = /(^|[#&])size=(\d+)x(\d+)/.exec(location.hash);
  function resize() {
    const w = fixedSize ? Number(fixedSize[2]) : view.clientWidth;
    const h = fixedSize ? Number(fixedSize[3]) : view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
  }
  function render() { renderer.render(scene, camera); }
  window.addEventListener('resize', () => { resize(); render(); });
  controls.addEventListener('change', render);

  // ---- playing ----
  let playing = false;
  let clock = 0;
  let exact = meta.first;
  function setPlaying(on) {
    playing = on && current < meta.last;
    play.textContent = playing ? '❚❚' : '▶';
    if (playing) { clock = performance.now(); exact = current; requestAnimationFrame(tick); }
  }
  async function tick(now) {
    if (!playing) return;
    exact += (now - clock) / 1000 / meta.dt * Number(speed.value);
    clock = now;
    const next = Math.min(meta.last, Math.floor(exact));
    if (next !== current) await show(next);
    if (current >= meta.last) { setPlaying(false); return; }
    requestAnimationFrame(tick);
  }
  play.onclick = () => setPlaying(!playing);
  slider.oninput = () => { setPlaying(false); show(Number(slider.value)); };
  window.addEventListener('keydown', (e) => {
    const step = e.shiftKey ? Math.round(1 / meta.dt) : 1;
    if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
    else if (e.key === 'ArrowRight') { setPlaying(false); show(current + step); }
    else if (e.key === 'ArrowLeft') { setPlaying(false); show(current - step); }
    else if (e.key === 'Home') { setPlaying(false); show(meta.first); }
    else if (e.key === 'End') { setPlaying(false); show(meta.last); }
  });

  // ---- for tests and tools: where things are on the screen ----
  // With "probe" in the URL's fragment, the page keeps a <pre id="detsim-probe"> with the frame
  // shown, its hash and each visible body's position on the drawing as fractions of its width and
  // height from the top left (what tests/viewer_test.py reads).
  const probe = /(^|[#&])probe(&|$)/.test(location.hash);
  function screenOf(object) {
    const v = object.getWorldPosition(new THREE.Vector3()).project(camera);
    return [Number(((v.x + 1) / 2).toFixed(4)), Number(((1 - v.y) / 2).toFixed(4))];
  }
  function writeProbe() {
    if (!probe) return;
    let pre = document.getElementById('detsim-probe');
    if (!pre) { pre = el('pre', { id: 'detsim-probe' }); pre.style.display = 'none'; document.body.append(pre); }
    const bodies = [];
    objects[0].forEach((o, k) => {
      if (o.object.visible && !o.half_space) bodies.push({ id: meta.bodies[k].id, screen: screenOf(o.object), red: o.red });
    });
    pre.textContent = JSON.stringify({ frame: current, hash: shown.hash[0][current - shown.first], bodies: bodies });
  }

  const start = /(^|[#&])frame=(\d+)/.exec(location.hash);
  resize();
  window.detsimView = { show: show, meta: meta, get frame() { return current; } };
  window.detsimView.ready = show(start ? Number(start[2]) : meta.first).then(() => {
    // Milliseconds from navigation (the page's request) to the first frame drawn, and the part of
    // them spent in this script (inflating, decoding and drawing).
    document.documentElement.dataset.loadMs = String(Math.round(performance.now()));
    document.documentElement.dataset.scriptMs = String(Math.round(performance.now() - started));
    document.documentElement.dataset.ready = 'yes';
    if (/(^|[#&])play(&|$)/.test(location.hash)) setPlaying(true);
  }).catch((e) => {
    panel.innerHTML = '<div class="bad">cannot show this match: ' + escapeHtml(e && e.message || e) + '</div>';
    document.documentElement.dataset.ready = 'error';
  });
})();
