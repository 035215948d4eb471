// crease's viewer (crates/crease/src/render/html.rs inlines it after three.js, which defines
// THREE and OrbitControls). The page's data: #meta (JSON) and base64 blocks; see html.rs.
const meta = JSON.parse(document.getElementById('meta').textContent);
const opts = new URLSearchParams(location.hash.slice(1));

const bytes = (id) => {
  const s = document.getElementById(id).textContent.trim();
  if (Uint8Array.fromBase64) return Uint8Array.fromBase64(s);
  const bin = atob(s), out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
};
const typed = (id, type, lo = 0, hi = 0) => {
  const b = bytes(id);
  if (type === 'q16') {
    // Floats quantised over [lo, hi]; 65535 marks a value that was not finite.
    const q = new Uint16Array(b.buffer, b.byteOffset, b.byteLength / 2);
    const out = new Float32Array(q.length);
    for (let i = 0; i < q.length; i++) out[i] = q[i] === 65535 ? NaN : lo + (q[i] / 65534) * (hi - lo);
    return out;
  }
  const T = {u8: Uint8Array, i16: Int16Array, i32: Int32Array, f32: Float32Array, u16: Uint16Array, u32: Uint32Array}[type];
  return new T(b.buffer, b.byteOffset, b.byteLength / T.BYTES_PER_ELEMENT);
};

// --- geometry -------------------------------------------------------------------------------
const n = meta.points;
const ext = [0, 1, 2].map((a) => meta.max[a] - meta.min[a]);
const diag = Math.hypot(...ext) || 1;
// Positions come as u16 per axis over the bounding box; the scene is centred on the box.
const dequantise = (q) => {
  const p = new Float32Array(q.length);
  for (let i = 0; i < q.length; i++) {
    const a = i % 3;
    p[i] = meta.min[a] + (q[i] / 65535) * ext[a] - meta.centre[a];
  }
  return p;
};
const pos = n > 0 ? dequantise(typed(meta.positions, 'u16')) : new Float32Array(0);
const attrValues = (a) => ({...a, values: typed(a.block, a.type, a.lo, a.hi)});
const pointAttrs = (meta.attributes || []).map(attrValues);
const faceAttrs = (meta.face_attributes || []).map(attrValues);
const rgb = meta.colors ? bytes(meta.colors) : null;
const faces = meta.faces ? typed(meta.faces, 'u32') : null;
const surfaces = new Map();
for (const s of (meta.surfaces && (meta.surfaces.surfaces || meta.surfaces)) || []) surfaces.set(s.id, s);

// Colours are shown as given (no sRGB / linear conversion): a legend swatch, a point and a line
// of the same RGB look the same.
THREE.ColorManagement.enabled = false;
const renderer = new THREE.WebGLRenderer({antialias: false, preserveDrawingBuffer: true});
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(innerWidth, innerHeight);
renderer.setClearColor(0x16161d, 1);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, innerWidth / innerHeight, diag / 1000, diag * 100);
// The first view: a scan in its scanner's frame (the origin outside the data, as a Kinect's or a
// RealSense's) is seen from the scanner; a part, from the isometric direction with Z up.
const origin = new THREE.Vector3(...meta.centre).negate();
const inside = [0, 1, 2].every((a) => meta.min[a] <= 0 && meta.max[a] >= 0);
const dir = !inside && origin.length() > 0 ? origin.clone().normalize() : new THREE.Vector3(1, -1.25, 0.9).normalize();
if (Math.abs(dir.z) > 0.9) camera.up.set(0, -1, 0); else camera.up.set(0, 0, 1);
const home = dir.clone().multiplyScalar(diag * 1.55);
camera.position.copy(home);
// Faces facing the camera keep about their colour, grazing ones darken (three.js' lights are in
// physical units: a Lambert surface lit with intensity I reflects colour × I / π... × π).
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const headlight = new THREE.DirectionalLight(0xffffff, 2.2);
camera.add(headlight);
scene.add(camera);

// A mesh with one vertex per face corner, so that each face has its own colour and a flat normal.
function faceMesh(p, f) {
  const m = f.length / 3;
  const q = new Float32Array(9 * m);
  for (let t = 0; t < m; t++)
    for (let k = 0; k < 3; k++) {
      const v = f[3 * t + k];
      for (let a = 0; a < 3; a++) q[9 * t + 3 * k + a] = p[3 * v + a];
    }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(q, 3));
  g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(9 * m), 3, true));
  g.computeVertexNormals();
  return new THREE.Mesh(g, new THREE.MeshLambertMaterial({vertexColors: true, side: THREE.DoubleSide}));
}
let cloud = null, mesh = null;
if (faces) {
  mesh = faceMesh(pos, faces);
  scene.add(mesh);
} else if (n > 0) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(3 * n), 3, true));
  // Squares 2.5 mean neighbour distances wide in the scene's units (so they shrink with
  // distance): a randomly sampled surface looks closed and hides what is behind it. three.js
  // scales an attenuated size by half the viewport height over the depth, without the field of
  // view: hence the division by tan(fov / 2). Without a spacing, a few pixels.
  const material = meta.spacing > 0
    ? new THREE.PointsMaterial({size: (2.5 * meta.spacing) / Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)),
      sizeAttenuation: true, vertexColors: true})
    : new THREE.PointsMaterial({size: n < 50000 ? 4 : n < 400000 ? 3 : 2, sizeAttenuation: false, vertexColors: true});
  cloud = new THREE.Points(g, material);
  scene.add(cloud);
}
const layers = (meta.layers || []).map((l) => {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(typed(l.block, 'f32'), 3));
  const color = new THREE.Color(`rgb(${l.color.join(',')})`);
  const obj = new THREE.LineSegments(g, new THREE.LineBasicMaterial({color, depthTest: false, toneMapped: false}));
  obj.renderOrder = 1;
  scene.add(obj);
  return {...l, obj};
});

// Further meshes (the B-rep's faces): per-face colours by surface type, each a layer.
const overlays = (meta.overlays || []).map((o) => {
  const obj = faceMesh(dequantise(typed(o.positions, 'u16')), typed(o.faces, 'u32'));
  const attrs = o.face_attributes.map(attrValues);
  scene.add(obj);
  return {...o, obj, attrs};
});

const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0, 0);
controls.update();
const render = () => renderer.render(scene, camera);
controls.addEventListener('change', render);
addEventListener('resize', () => {
  camera.aspect = innerWidth / innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(innerWidth, innerHeight);
  render();
});

// --- colours --------------------------------------------------------------------------------
const NAMES = {
  surface_type: {0: 'plane', 1: 'cylinder', 2: 'cone', 3: 'sphere', 4: 'torus', 255: 'unassigned'},
  sharp: {0: 'not sharp', 1: 'sharp'},
};
const UNASSIGNED = [70, 70, 78];
const PALETTE = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [148, 103, 189], [140, 86, 75], [227, 119, 194],
  [188, 189, 34], [23, 190, 207], [174, 199, 232], [255, 187, 120], [152, 223, 138], [197, 176, 213],
  [196, 156, 148], [247, 182, 210], [219, 219, 141], [158, 218, 229], [57, 59, 121], [99, 121, 57],
  [140, 109, 49], [123, 65, 115]];
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
const viridis = (t) => {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1), i = Math.min(Math.floor(x), VIRIDIS.length - 2), f = x - i;
  return VIRIDIS[i].map((c, k) => Math.round(c + f * (VIRIDIS[i + 1][k] - c)));
};
const hashed = (v) => {
  const h = (Math.imul(v | 0, 2654435761) >>> 0) / 4294967296;
  return new THREE.Color().setHSL(h, 0.65, 0.55).toArray().map((c) => Math.round(c * 255));
};
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;'}[c]));
const swatch = (c) => `<span class="swatch" style="background:rgb(${c.join(',')})"></span>`;
const unassigned = (name, v) => v === -1 || (v === 255 && name !== 'sharp');

/// Colours of `values` (one per element) into `out` (3 bytes each); returns the legend's HTML.
function colourise(attr, out) {
  const count = out.length / 3;
  const set = (i, c) => { out[3 * i] = c[0]; out[3 * i + 1] = c[1]; out[3 * i + 2] = c[2]; };
  if (!attr) {
    for (let i = 0; i < count; i++) set(i, [170, 178, 190]);
    return '';
  }
  if (attr === 'rgb') {
    out.set(rgb.subarray(0, out.length));
    return 'stored colours';
  }
  const v = attr.values, name = attr.name;
  if (attr.kind === 'flag') {
    const c = [[175, 175, 180], [255, 140, 0]], k = [0, 0];
    for (let i = 0; i < count; i++) { const b = v[i] ? 1 : 0; set(i, c[b]); k[b]++; }
    const label = NAMES[name] || {0: 'no', 1: 'yes'};
    return [0, 1].map((b) => `${swatch(c[b])}${esc(label[b])}: ${k[b].toLocaleString()}`).join('<br>');
  }
  if (attr.kind === 'int') {
    const counts = new Map();
    for (let i = 0; i < count; i++) counts.set(v[i], (counts.get(v[i]) || 0) + 1);
    const keys = [...counts.keys()].sort((a, b) => a - b);
    const assigned = keys.filter((k) => !unassigned(name, k));
    const few = assigned.length <= PALETTE.length;
    const colour = new Map(keys.map((k) => [k, unassigned(name, k) ? UNASSIGNED
      : few ? PALETTE[assigned.indexOf(k)] : hashed(k)]));
    for (let i = 0; i < count; i++) set(i, colour.get(v[i]));
    const label = (k) => (NAMES[name] && NAMES[name][k]) || (unassigned(name, k) ? 'none' : `${name} ${k}`);
    if (!few) return `${assigned.length.toLocaleString()} distinct values (hashed colours)`;
    return keys.map((k) => `${swatch(colour.get(k))}${esc(label(k))}: ${counts.get(k).toLocaleString()}`).join('<br>');
  }
  // Floats: viridis between the 1st and 99th percentiles of a sample.
  const sample = [];
  const step = Math.max(1, Math.floor(count / 100000));
  for (let i = 0; i < count; i += step) if (Number.isFinite(v[i])) sample.push(v[i]);
  sample.sort((a, b) => a - b);
  const lo = sample.length ? sample[Math.floor(0.01 * (sample.length - 1))] : 0;
  const hi = sample.length ? sample[Math.ceil(0.99 * (sample.length - 1))] : 1;
  const span = hi > lo ? hi - lo : 1;
  for (let i = 0; i < count; i++) set(i, Number.isFinite(v[i]) ? viridis((v[i] - lo) / span) : UNASSIGNED);
  const stops = VIRIDIS.map((c) => `rgb(${c.join(',')})`).join(',');
  return `${esc(name)}<div class="bar" style="background:linear-gradient(90deg,${stops})"></div>` +
    `<div class="ends"><span>${lo.toPrecision(4)}</span><span>${hi.toPrecision(4)}</span></div>`;
}

const attrs = mesh ? faceAttrs : pointAttrs;
function colourBy(name) {
  const attr = name === 'rgb' ? 'rgb' : attrs.find((a) => a.name === name) || null;
  const target = mesh || cloud;
  if (!target) return;
  const c = target.geometry.getAttribute('color');
  let legend;
  if (mesh) {
    const per = new Uint8Array(faces.length);
    legend = colourise(attr, per);
    for (let f = 0; f < faces.length / 3; f++)
      for (let k = 0; k < 3; k++) c.array.set(per.subarray(3 * f, 3 * f + 3), 9 * f + 3 * k);
  } else {
    legend = colourise(attr, c.array);
  }
  c.needsUpdate = true;
  document.getElementById('legend').innerHTML = legend;
  render();
}

// --- the panel ------------------------------------------------------------------------------
const controlsDiv = document.getElementById('controls');
const choices = [...(rgb && !mesh ? ['rgb'] : []), ...attrs.map((a) => a.name), 'none'];
const initial = opts.get('color') || meta.color_by ||
  (attrs.some((a) => a.name === 'surface') ? 'surface' : rgb && !mesh ? 'rgb' : 'none');
controlsDiv.innerHTML = `<label>colour by <select id="color">${choices.map((c) =>
  `<option value="${esc(c)}"${c === initial ? ' selected' : ''}>${c === 'rgb' ? 'stored colours' : c === 'none' ? 'one colour' : esc(c)}</option>`).join('')}</select></label>`;
const toggle = (id, label, obj, on) => {
  const l = document.createElement('label');
  l.innerHTML = `<input type="checkbox" id="${esc(id)}"${on ? ' checked' : ''}> ${label}`;
  controlsDiv.appendChild(l);
  obj.visible = on;
  l.querySelector('input').addEventListener('change', (e) => { obj.visible = e.target.checked; render(); });
};
if (mesh) toggle('faces', `faces (${(faces.length / 3).toLocaleString()})`, mesh, opts.get('faces') !== 'off');
if (cloud) toggle('points', `points (${n.toLocaleString()})`, cloud, opts.get('points') !== 'off');
for (const l of layers)
  toggle(`layer-${l.name}`, `${swatch(l.color)}${esc(l.name)} (${l.polylines})`, l.obj, opts.get(`layer-${l.name}`) !== 'off');
for (const o of overlays)
  toggle(`layer-${o.name}`, `${esc(o.name)} (${o.face_count.toLocaleString()} triangles)`, o.obj,
    opts.get(`layer-${o.name}`) ? opts.get(`layer-${o.name}`) !== 'off' : o.visible);
const reset = document.createElement('button');
reset.textContent = 'reset view';
reset.addEventListener('click', () => { camera.position.copy(home); controls.target.set(0, 0, 0); controls.update(); render(); });
controlsDiv.appendChild(reset);
document.getElementById('color').addEventListener('change', (e) => colourBy(e.target.value));
document.getElementById('note').textContent = [
  ...(meta.total_points > meta.points
    ? [`showing ${meta.points.toLocaleString()} of ${meta.total_points.toLocaleString()} points (an even subsample)`] : []),
  ...(meta.left_out || []),
].join('; ');

// --- picking --------------------------------------------------------------------------------
const raycaster = new THREE.Raycaster();
const fmt = (x) => (typeof x === 'number' ? (Number.isInteger(x) ? String(x) : x.toPrecision(6))
  : Array.isArray(x) ? `[${x.map(fmt).join(', ')}]` : x && typeof x === 'object'
    ? Object.entries(x).map(([k, y]) => `${k}: ${fmt(y)}`).join(', ') : String(x));
function describe(kind, index, list) {
  const lines = [`${kind} ${index}`];
  let surface = null;
  for (const a of list) {
    const v = a.values[index];
    const named = NAMES[a.name] && NAMES[a.name][v];
    lines.push(`${a.name}: ${named !== undefined ? named : fmt(v)}`);
    if (a.name === 'surface') surface = surfaces.get(v);
  }
  if (surface) {
    lines.push('', `surface ${surface.id}: ${surface.type}`);
    if (surface.params) lines.push(fmt(surface.params));
    const count = surface.vertices !== undefined ? surface.vertices : surface.points;
    if (count !== undefined) lines.push(`points: ${count}`);
    if (surface.rms !== undefined) lines.push(`RMS: ${fmt(surface.rms)}`);
  }
  return lines.join('\n');
}
function pick(x, y) {
  const r = renderer.domElement.getBoundingClientRect();
  raycaster.setFromCamera(new THREE.Vector2(((x - r.left) / r.width) * 2 - 1, -((y - r.top) / r.height) * 2 + 1), camera);
  // Points within 5 pixels of the cursor at the orbit target's depth.
  const depth = camera.position.distanceTo(controls.target);
  const perPixel = (2 * depth * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2))) / r.height;
  raycaster.params.Points.threshold = 5 * perPixel;
  const info = document.getElementById('info');
  const shown = overlays.filter((o) => o.obj.visible);
  const over = shown.length ? raycaster.intersectObjects(shown.map((o) => o.obj))[0] : undefined;
  if (over) {
    const o = shown.find((x) => x.obj === over.object);
    info.textContent = describe(`${o.name}: triangle`, over.faceIndex, o.attrs);
    info.style.display = 'block';
    return;
  }
  const target = mesh && mesh.visible ? mesh : cloud && cloud.visible ? cloud : null;
  const hit = target ? raycaster.intersectObject(target)[0] : undefined;
  if (!hit) { info.style.display = 'none'; return; }
  info.textContent = mesh ? describe('face', hit.faceIndex, faceAttrs)
    : describe(meta.total_points > meta.points ? 'point (of the subsample)' : 'point', hit.index, pointAttrs);
  info.style.display = 'block';
}
let down = null;
renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
renderer.domElement.addEventListener('pointerup', (e) => {
  if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) < 4) pick(e.clientX, e.clientY);
  down = null;
});

for (const o of overlays) {
  const type = o.attrs.find((a) => a.name === 'surface_type');
  const per = new Uint8Array(3 * o.face_count);
  colourise(type || null, per);
  const c = o.obj.geometry.getAttribute('color');
  for (let f = 0; f < o.face_count; f++)
    for (let k = 0; k < 3; k++) c.array.set(per.subarray(3 * f, 3 * f + 3), 9 * f + 3 * k);
  c.needsUpdate = true;
}
colourBy(initial);
render();
if (opts.get('click')) {
  const [x, y] = opts.get('click').split(',').map(Number);
  pick(x, y);
}
// Two frames later the picture is on screen (the browser tests wait for this mark).
requestAnimationFrame(() => requestAnimationFrame(() => { document.body.dataset.ready = '1'; }));
