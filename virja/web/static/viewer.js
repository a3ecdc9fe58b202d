// virja's browser viewer: the band as the native renderer draws it, fed over a WebSocket.
//
// The server sends, once, the unit meshes, the stage's instances, the camera presets and
// the lights (a JSON "hello"), and then, per frame, the moving instances at a session
// time a little ahead of now (binary, see virja/web/frames.py).  The page keeps an
// estimate of the session clock (ping/pong) and draws, at each refresh, the moment it
// shows, interpolated between the two frames around it.  The shader is the native
// renderer's own shaders/solid.glsl.
//
// URL parameters: camera=front|drums|bass|top, transparent=1, floor=0|1, status=0, fps=N
// (cap the drawing rate), ws=URL.
// Keys: 1-4 cameras, arrows orbit, +/- zoom, H status line, F fullscreen.  Drag to orbit,
// wheel to zoom.

import * as THREE from '/three/three.module.js';

const params = new URLSearchParams(location.search);
const flag = (name, dflt) => {
  if (!params.has(name)) return dflt;
  return !['0', 'false', 'no', 'off'].includes(params.get(name).toLowerCase());
};
const transparent = flag('transparent', false);
const showFloor = flag('floor', !transparent);
const statusEl = document.getElementById('status');
if (!flag('status', true)) statusEl.classList.add('hidden');
if (transparent) document.body.classList.add('transparent');
const minFrameMs = params.has('fps') ? 1000 / Math.max(1, Number(params.get('fps')) || 60) : 0;
const wsUrl = params.get('ws') || `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;

// float16 -> float32, once
const F16 = new Float32Array(65536);
for (let h = 0; h < 65536; h++) {
  const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 0x1f, f = h & 0x3ff;
  F16[h] = e === 0 ? s * f * 2 ** -24 : e === 31 ? (f ? NaN : s * Infinity) : s * (1 + f / 1024) * 2 ** (e - 15);
}

THREE.ColorManagement.enabled = false; // colours and the clear colour are used as sent
const renderer = new THREE.WebGLRenderer({ antialias: true, alpha: transparent, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.prepend(renderer.domElement);
const scene = new THREE.Scene();
const camera3 = new THREE.PerspectiveCamera(42, window.innerWidth / window.innerHeight, 0.05, 60);
window.addEventListener('resize', () => renderer.setSize(window.innerWidth, window.innerHeight));

const stats = {
  frames: 0, bytes: 0, draws: 0, lateDraws: 0, margins: [], offset: null, rtt: null,
  connected: false, hello: false, instances: 0,
};
window.virjaStats = stats;
// the picture as drawn, every step-th pixel, top row first, RGBA bytes in base64 (tests, tools)
window.virjaPixels = (step = 2) => {
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
  const buf = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, buf);
  let bin = '';
  for (let y = h - 1; y >= 0; y -= step) {
    for (let x = 0; x < w; x += step) {
      const i = (y * w + x) * 4;
      bin += String.fromCharCode(buf[i], buf[i + 1], buf[i + 2], buf[i + 3]);
    }
  }
  return { w: Math.ceil(w / step), h: Math.ceil(h / step), rgba: btoa(bin) };
};

// --- the orbit camera, as virja/render/camera.py --------------------------------------
let presets = {};
let cam = null;
function orbit(dYaw, dPitch) {
  cam.yaw_deg = (((cam.yaw_deg + dYaw) % 360) + 360) % 360;
  cam.pitch_deg = Math.min(85, Math.max(-10, cam.pitch_deg + dPitch));
}
function zoom(f) { cam.distance_m = Math.min(30, Math.max(1, cam.distance_m * f)); }
function usePreset(name) { if (presets[name]) cam = structuredClone(presets[name]); }
function placeCamera(w, h) {
  const yaw = THREE.MathUtils.degToRad(cam.yaw_deg), pitch = THREE.MathUtils.degToRad(cam.pitch_deg);
  const [tx, ty, tz] = cam.target;
  camera3.fov = cam.fov_deg; camera3.near = cam.near_m; camera3.far = cam.far_m;
  camera3.aspect = w / Math.max(h, 1);
  camera3.position.set(
    tx + cam.distance_m * Math.sin(yaw) * Math.cos(pitch),
    ty + cam.distance_m * Math.sin(pitch),
    tz + cam.distance_m * Math.cos(yaw) * Math.cos(pitch));
  camera3.up.set(0, 1, 0);
  camera3.lookAt(tx, ty, tz);
  camera3.updateProjectionMatrix();
  camera3.updateMatrixWorld();
}

let dragging = null;
renderer.domElement.addEventListener('pointerdown', (e) => { dragging = [e.clientX, e.clientY]; renderer.domElement.setPointerCapture(e.pointerId); });
renderer.domElement.addEventListener('pointerup', () => { dragging = null; });
renderer.domElement.addEventListener('pointermove', (e) => {
  if (!dragging || !cam) return;
  orbit(-(e.clientX - dragging[0]) * 0.3, (e.clientY - dragging[1]) * 0.3);
  dragging = [e.clientX, e.clientY];
});
renderer.domElement.addEventListener('wheel', (e) => { if (cam) zoom(0.9 ** (-e.deltaY / 100)); e.preventDefault(); }, { passive: false });
window.addEventListener('keydown', (e) => {
  if (!cam) return;
  const keys = { 1: 'front', 2: 'drums', 3: 'bass', 4: 'top' };
  if (keys[e.key]) usePreset(keys[e.key]);
  else if (e.key === 'ArrowLeft') orbit(5, 0);
  else if (e.key === 'ArrowRight') orbit(-5, 0);
  else if (e.key === 'ArrowUp') orbit(0, 5);
  else if (e.key === 'ArrowDown') orbit(0, -5);
  else if (e.key === '+' || e.key === '=') zoom(0.9);
  else if (e.key === '-') zoom(1 / 0.9);
  else if (e.key === 'h' || e.key === 'H') statusEl.classList.toggle('hidden');
  else if (e.key === 'f' || e.key === 'F') {
    if (document.fullscreenElement) document.exitFullscreen(); else document.documentElement.requestFullscreen();
  }
});

// --- meshes and instances ----------------------------------------------------------------
let material = null;
let kinds = [];
const meshes = {};      // kind -> Float32Array of (position, normal) per vertex
const dynamic = {};     // kind -> { mesh, model, color, capacity }
let staticGroup = null;
let shaderSource = null;

async function loadShader() {
  const res = await fetch('/solid.glsl');
  if (!res.ok) throw new Error(`solid.glsl: HTTP ${res.status}`);
  shaderSource = await res.text();
}

function makeMaterial(hello) {
  const unit = (v) => new THREE.Vector3(...v).normalize();
  const bg = hello.background;
  const head = (stage) => `precision highp float;\n#define ${stage}\n`;
  return new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader: head('VERTEX_SHADER') + shaderSource,
    fragmentShader: head('FRAGMENT_SHADER') + shaderSource,
    uniforms: {
      u_view_proj: { value: new THREE.Matrix4() },
      u_eye: { value: new THREE.Vector3() },
      u_key_dir: { value: unit(hello.lights.u_key_dir) },
      u_fill_dir: { value: unit(hello.lights.u_fill_dir) },
      u_spot_pos: { value: new THREE.Vector3(...hello.lights.u_spot_pos) },
      u_fog_color: { value: new THREE.Vector3(bg[0], bg[1], bg[2]) },
    },
  });
}

function geometryFor(kind, model, color) {
  const g = new THREE.InstancedBufferGeometry();
  const buf = new THREE.InterleavedBuffer(meshes[kind], 6);
  const pos = new THREE.InterleavedBufferAttribute(buf, 3, 0);
  g.setAttribute('in_position', pos);
  g.setAttribute('position', pos); // three counts vertices by 'position'
  g.setAttribute('in_normal', new THREE.InterleavedBufferAttribute(buf, 3, 3));
  g.setAttribute('in_model', model);
  g.setAttribute('in_color', color);
  return g;
}

function addMesh(geometry, parent) {
  const m = new THREE.Mesh(geometry, material);
  m.frustumCulled = false;
  parent.add(m);
  return m;
}

function buildStatic(hello) {
  if (staticGroup) { scene.remove(staticGroup); staticGroup.traverse((o) => o.geometry && o.geometry.dispose()); }
  staticGroup = new THREE.Group();
  for (const kind of kinds) {
    const rows = hello.static[kind].rows, stage = hello.static[kind].stage;
    const keep = [];
    for (let i = 0; i < stage.length; i++) if (showFloor || !stage[i]) keep.push(i);
    if (!keep.length) continue;
    const model = new Float32Array(keep.length * 16), color = new Float32Array(keep.length * 4);
    keep.forEach((i, j) => {
      for (let k = 0; k < 16; k++) model[j * 16 + k] = rows[i * 20 + k];
      for (let k = 0; k < 4; k++) color[j * 4 + k] = rows[i * 20 + 16 + k];
    });
    const g = geometryFor(kind, new THREE.InstancedBufferAttribute(model, 16), new THREE.InstancedBufferAttribute(color, 4));
    g.instanceCount = keep.length;
    addMesh(g, staticGroup);
  }
  scene.add(staticGroup);
}

function ensureDynamic(kind, n) {
  let d = dynamic[kind];
  if (d && d.capacity >= n) return d;
  const capacity = Math.max(64, 2 ** Math.ceil(Math.log2(Math.max(n, 1))));
  if (d) { scene.remove(d.mesh); d.mesh.geometry.dispose(); }
  const model = new THREE.InstancedBufferAttribute(new Float32Array(capacity * 16), 16);
  const color = new THREE.InstancedBufferAttribute(new Uint8Array(capacity * 4), 4, true);
  model.setUsage(THREE.DynamicDrawUsage); color.setUsage(THREE.DynamicDrawUsage);
  const g = geometryFor(kind, model, color);
  g.instanceCount = 0;
  d = { mesh: addMesh(g, scene), model, color, capacity };
  dynamic[kind] = d;
  return d;
}

// --- frames ------------------------------------------------------------------------------
const frames = []; // { t, counts, model: Float32Array(n*16), color: Uint8Array(n*4) }, by time
const HEADER = 24;

function decodeFrame(buf) {
  const dv = new DataView(buf);
  if (dv.getUint8(0) !== 2 || dv.getUint8(1) !== 1) return null;
  const t = dv.getFloat64(8, true);
  const counts = [dv.getUint16(16, true), dv.getUint16(18, true), dv.getUint16(20, true)];
  const n = counts[0] + counts[1] + counts[2];
  if (buf.byteLength !== HEADER + 28 * n) return null;
  const lin = new Uint16Array(buf, HEADER, 9 * n);
  const pos = new Int16Array(buf, HEADER + 18 * n, 3 * n);
  const color = new Uint8Array(buf, HEADER + 24 * n, 4 * n);
  const model = new Float32Array(16 * n);
  const scale = 1 / posScale;
  for (let i = 0; i < n; i++) {
    const m = 16 * i, l = 9 * i, p = 3 * i;
    model[m] = F16[lin[l]]; model[m + 1] = F16[lin[l + 1]]; model[m + 2] = F16[lin[l + 2]];
    model[m + 4] = F16[lin[l + 3]]; model[m + 5] = F16[lin[l + 4]]; model[m + 6] = F16[lin[l + 5]];
    model[m + 8] = F16[lin[l + 6]]; model[m + 9] = F16[lin[l + 7]]; model[m + 10] = F16[lin[l + 8]];
    model[m + 12] = pos[p] * scale; model[m + 13] = pos[p + 1] * scale; model[m + 14] = pos[p + 2] * scale;
    model[m + 15] = 1;
  }
  return { t, counts, model, color };
}

function addFrame(f) {
  let i = frames.length;
  while (i > 0 && frames[i - 1].t > f.t) i--;
  frames.splice(i, 0, f);
  if (frames.length > 32) frames.splice(0, frames.length - 32);
}

function showFrames(T) {
  if (!frames.length) return;
  let i = frames.length - 1;
  while (i > 0 && frames[i].t > T) i--;
  const a = frames[i], b = frames[i + 1];
  if (i > 1) frames.splice(0, i - 1); // keep one older frame
  if (T > frames[frames.length - 1].t) stats.lateDraws++;
  // interpolate each kind whose instance count is the same in both frames; a kind whose
  // count changed (a string starting to vibrate adds segments) shows the nearer frame
  let w = 0;
  if (b && T > a.t) w = Math.min(1, (T - a.t) / (b.t - a.t));
  let offA = 0, offB = 0;
  stats.instances = 0;
  kinds.forEach((kind, k) => {
    const near = b && w >= 0.5 ? b : a;
    const offNear = near === a ? offA : offB;
    const n = near.counts[k];
    const d = ensureDynamic(kind, n);
    const dst = d.model.array;
    if (b && w > 0 && a.counts[k] === b.counts[k]) {
      for (let j = 0; j < n * 16; j++) {
        const x = a.model[offA * 16 + j];
        dst[j] = x + (b.model[offB * 16 + j] - x) * w;
      }
    } else dst.set(near.model.subarray(offNear * 16, (offNear + n) * 16));
    d.color.array.set(near.color.subarray(offNear * 4, (offNear + n) * 4));
    d.model.needsUpdate = true; d.color.needsUpdate = true;
    d.mesh.geometry.instanceCount = n;
    offA += a.counts[k];
    if (b) offB += b.counts[k];
    stats.instances += n;
  });
}

// --- the session clock ------------------------------------------------------------------
const samples = [];
let offset = null;
function sessionNow() { return offset === null ? null : performance.now() / 1000 + offset; }
function onPong(msg) {
  const t1 = performance.now();
  const rtt = (t1 - msg.c) / 1000;
  samples.push({ rtt, offset: msg.s - (msg.c + t1) / 2000 });
  if (samples.length > 12) samples.shift();
  const best = samples.reduce((x, y) => (y.rtt < x.rtt ? y : x));
  offset = best.offset; stats.offset = offset; stats.rtt = best.rtt;
}

// --- status line ---------------------------------------------------------------------------
let beats = [], chords = [];
const latest = (list, T) => { let r = null; for (const x of list) if (x.t <= T) r = x; else break; return r; };
function insertByTime(list, x) {
  let i = list.length;
  while (i > 0 && list[i - 1].t > x.t) i--;
  list.splice(i, 0, x);
  if (list.length > 64) list.shift();
}
function statusText(T) {
  const parts = [];
  const b = T === null ? null : latest(beats, T);
  const c = T === null ? null : latest(chords, T);
  parts.push(b && b.bpm ? `♩ = ${Math.round(b.bpm)}` : '♩ = –');
  parts.push(b ? `bar ${b.bar}.${b.beat}` : 'bar –');
  parts.push(c ? c.name : '–');
  parts.push(stats.connected ? 'connected' : 'not connected');
  return parts.join('   ');
}

// --- the connection -------------------------------------------------------------------------
let posScale = 4096;
let retry = 500;
let pingTimer = null;
function connect() {
  const ws = new WebSocket(wsUrl);
  ws.binaryType = 'arraybuffer';
  let pings = 0;
  const ping = () => {
    if (ws.readyState !== WebSocket.OPEN) return;
    ws.send(JSON.stringify({ type: 'ping', c: performance.now() }));
    pings++;
    pingTimer = setTimeout(ping, pings < 8 ? 150 : 1000);
  };
  ws.onopen = () => { stats.connected = true; retry = 500; ping(); };
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') {
      const f = decodeFrame(ev.data);
      if (!f) return;
      stats.frames++; stats.bytes += ev.data.byteLength;
      const now = sessionNow();
      if (now !== null) { stats.margins.push(f.t - now); if (stats.margins.length > 600) stats.margins.shift(); }
      addFrame(f);
      return;
    }
    const msg = JSON.parse(ev.data);
    if (msg.type === 'pong') onPong(msg);
    else if (msg.type === 'beat') insertByTime(beats, msg);
    else if (msg.type === 'chord') insertByTime(chords, msg);
    else if (msg.type === 'hello') {
      kinds = msg.kinds; posScale = msg.pos_scale;
      for (const k of kinds) meshes[k] = new Float32Array(msg.meshes[k]);
      presets = msg.cameras;
      if (!cam) usePreset(presets[params.get('camera')] ? params.get('camera') : 'front');
      if (!material) material = makeMaterial(msg);
      const bg = msg.background;
      renderer.setClearColor(new THREE.Color(bg[0], bg[1], bg[2]), transparent ? 0 : 1);
      for (const k of Object.keys(dynamic)) { scene.remove(dynamic[k].mesh); dynamic[k].mesh.geometry.dispose(); delete dynamic[k]; }
      buildStatic(msg);
      stats.hello = true;
    }
  };
  ws.onclose = () => {
    stats.connected = false;
    clearTimeout(pingTimer);
    setTimeout(connect, retry);
    retry = Math.min(retry * 2, 5000);
  };
}

let lastDrawMs = -Infinity;
function draw(nowMs) {
  requestAnimationFrame(draw);
  if (nowMs - lastDrawMs < minFrameMs - 1) return;
  lastDrawMs = nowMs;
  const T = sessionNow();
  statusEl.textContent = statusText(T);
  if (!material || !cam) return;
  if (T !== null) showFrames(T);
  const size = renderer.getSize(new THREE.Vector2());
  placeCamera(size.x, size.y);
  material.uniforms.u_view_proj.value.multiplyMatrices(camera3.projectionMatrix, camera3.matrixWorldInverse);
  material.uniforms.u_eye.value.copy(camera3.position);
  renderer.render(scene, camera3);
  stats.draws++;
}

loadShader().then(() => { connect(); requestAnimationFrame(draw); }).catch((e) => { statusEl.textContent = `virja viewer: ${e.message}`; console.error(e); });
