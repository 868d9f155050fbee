// flexmbd's browser viewer: the script of the page `flexmbd view` writes (viewer/html_viewer.cpp
// puts it there with three.js and the data; docs/viewer.md). An ES module, ASCII only.
// The page reports how it went in the element of id flexmbd-status (JSON: frames, bodies,
// errors, pixels drawn), which the browser test reads (tests/test_viewer.cpp).

const errors = [];
window.addEventListener('error', (e) => errors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => errors.push(String(e.reason)));
const consoleError = console.error;
console.error = (...args) => {
  errors.push(args.map(String).join(' '));
  consoleError.apply(console, args);
};

const BACKGROUND = 0xf3f4f6;
const BODY_COLOURS = [0x3b6ea8, 0xd1803a, 0x4f9a58, 0xb8453f, 0x7e62a8, 0x8c6a4f, 0xc86fa8, 0x6b6b6b, 0xa8a23b, 0x3ba8a1];
// a perceptually ordered colour map (dark blue, blue, green, yellow), linear between stops
const MAP = [[0.267, 0.005, 0.329], [0.231, 0.322, 0.545], [0.129, 0.569, 0.549], [0.369, 0.788, 0.384], [0.992, 0.906, 0.145]];

function el(tag, attrs = {}, parent = null, text = null) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== null) e.textContent = text;
  if (parent) parent.appendChild(e);
  return e;
}

function float32(b64) {
  if (!b64) return null;
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  return new Float32Array(bytes.buffer);
}

function colourAt(s) {
  const x = Math.min(Math.max(s, 0), 1) * (MAP.length - 1);
  const k = Math.min(Math.floor(x), MAP.length - 2);
  const f = x - k;
  return MAP[k].map((a, i) => a + f * (MAP[k + 1][i] - a));
}

function fmt(v) {
  if (!isFinite(v)) return String(v);
  const a = Math.abs(v);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : String(Number(v.toPrecision(4)));
}

async function loadThree() {
  // three.js is in the page as text: imported from a blob URL (file:// pages cannot import files)
  const src = document.getElementById('three-src').textContent;
  return import(URL.createObjectURL(new Blob([src], { type: 'text/javascript' })));
}

// ----- the page's data ----------------------------------------------------------------------

function readData() {
  const data = JSON.parse(document.getElementById('flexmbd-data').textContent);
  for (const c of data.clips) {
    c.pos = float32(c.positions);
    c.disp = float32(c.displacements);
    c.jpos = float32(c.joint_positions);
    c.jaxes = float32(c.joint_axes);
    c.q = c.quantities.map(float32);
    c.frames = c.times.length;
  }
  return data;
}

/// Centre, size and the smallest/largest coordinate along `up` over every frame of every clip.
function extent(data) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const c of data.clips) {
    for (const arr of [c.pos, c.jpos]) {
      if (!arr) continue;  // no joints: an empty array
      for (let i = 0; i < arr.length; i += 3) {
        for (let k = 0; k < 3; ++k) {
          lo[k] = Math.min(lo[k], arr[i + k]);
          hi[k] = Math.max(hi[k], arr[i + k]);
        }
      }
    }
  }
  const size = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  return { lo, hi, centre: lo.map((l, k) => 0.5 * (l + hi[k])), size };
}

// ----- the scene ----------------------------------------------------------------------------

class Model {
  constructor(THREE, data, box) {
    this.THREE = THREE;
    this.data = data;
    this.group = new THREE.Group();
    const L = box.size;
    // poly-lines as tubes: one instance per segment
    this.segments = [];
    this.polygons = [];
    data.cells.forEach((cell, k) => {
      if (data.cell_kinds[k] === 1) {
        for (let i = 1; i + 1 < cell.length; ++i) this.polygons.push(cell[0], cell[i], cell[i + 1]);
      } else {
        for (let i = 0; i + 1 < cell.length; ++i) this.segments.push([cell[i], cell[i + 1], data.cell_body[k]]);
      }
    });
    this.radius = 0.006 * L;
    const cyl = new THREE.CylinderGeometry(1, 1, 1, 12, 1, false);
    this.tubes = new THREE.InstancedMesh(cyl, new THREE.MeshStandardMaterial({ roughness: 0.5, metalness: 0.1 }),
                                         Math.max(this.segments.length, 1));
    this.tubes.count = this.segments.length;
    this.group.add(this.tubes);
    // polygons: one indexed mesh over all points (flat shading: no normals to keep)
    this.surface = new THREE.BufferGeometry();
    this.surfacePositions = new THREE.BufferAttribute(new Float32Array(3 * data.points), 3);
    this.surfaceColours = new THREE.BufferAttribute(new Float32Array(3 * data.points), 3);
    this.surface.setAttribute('position', this.surfacePositions);
    this.surface.setAttribute('color', this.surfaceColours);
    this.surface.setIndex(this.polygons);
    const surfaceMesh = new THREE.Mesh(this.surface, new THREE.MeshStandardMaterial({
      vertexColors: true, flatShading: true, side: THREE.DoubleSide, roughness: 0.6 }));
    surfaceMesh.frustumCulled = false;
    if (this.polygons.length) this.group.add(surfaceMesh);
    // joints: spheres, and their axes as lines
    const nj = data.joints.length;
    this.joints = new THREE.InstancedMesh(new THREE.SphereGeometry(0.014 * L, 16, 12),
                                          new THREE.MeshStandardMaterial({ color: 0x30343a }), Math.max(nj, 1));
    this.joints.count = nj;
    this.group.add(this.joints);
    this.axisLength = 0.05 * L;
    this.axes = new THREE.BufferGeometry();
    this.axisPositions = new THREE.BufferAttribute(new Float32Array(6 * Math.max(nj, 1)), 3);
    this.axes.setAttribute('position', this.axisPositions);
    const axisLines = new THREE.LineSegments(this.axes, new THREE.LineBasicMaterial({ color: 0xc0392b }));
    axisLines.frustumCulled = false;
    this.group.add(axisLines);
    this.pointBody = new Int32Array(data.points).fill(-1);
    data.cells.forEach((cell, k) => { for (const i of cell) this.pointBody[i] = data.cell_body[k]; });
    this.m = new THREE.Matrix4();
    this.v = new THREE.Vector3();
    this.up = new THREE.Vector3(0, 1, 0);
    this.quat = new THREE.Quaternion();
    this.colour = new THREE.Color();
  }

  /// Draws frame f of clip c, elastic displacements times `scale`, coloured by quantity
  /// index `qi` (-1: by body).
  show(c, f, scale, qi) {
    const THREE = this.THREE;
    const n = this.data.points;
    const p = c.pos.subarray(3 * n * f, 3 * n * (f + 1));
    const u = c.disp ? c.disp.subarray(3 * n * f, 3 * n * (f + 1)) : null;
    const at = (i, k) => p[3 * i + k] + (u && scale !== 1 ? (scale - 1) * u[3 * i + k] : 0);
    const quantity = qi >= 0 ? this.data.quantities[qi] : null;
    const values = quantity ? c.q[qi].subarray(n * f, n * (f + 1)) : null;
    const span = quantity ? (quantity.max - quantity.min) || 1 : 1;
    const colourOf = (i, body) => {
      if (values) return colourAt((values[i] - quantity.min) / span);
      this.colour.setHex(BODY_COLOURS[body % BODY_COLOURS.length]);
      return [this.colour.r, this.colour.g, this.colour.b];
    };
    const a = new THREE.Vector3(), b = new THREE.Vector3();
    this.segments.forEach(([i, j, body], s) => {
      a.set(at(i, 0), at(i, 1), at(i, 2));
      b.set(at(j, 0), at(j, 1), at(j, 2));
      this.v.subVectors(b, a);
      const len = this.v.length();
      this.quat.setFromUnitVectors(this.up, len > 0 ? this.v.clone().divideScalar(len) : this.up);
      this.m.compose(a.add(b).multiplyScalar(0.5), this.quat, new THREE.Vector3(this.radius, len, this.radius));
      this.tubes.setMatrixAt(s, this.m);
      const ci = colourOf(i, body), cj = colourOf(j, body);
      this.tubes.setColorAt(s, this.colour.setRGB(0.5 * (ci[0] + cj[0]), 0.5 * (ci[1] + cj[1]), 0.5 * (ci[2] + cj[2])));
    });
    this.tubes.instanceMatrix.needsUpdate = true;
    if (this.tubes.instanceColor) this.tubes.instanceColor.needsUpdate = true;
    if (this.polygons.length) {
      for (let i = 0; i < n; ++i) {
        for (let k = 0; k < 3; ++k) this.surfacePositions.array[3 * i + k] = at(i, k);
        const col = colourOf(i, Math.max(this.pointBody[i], 0));
        this.surfaceColours.array.set(col, 3 * i);
      }
      this.surfacePositions.needsUpdate = true;
      this.surfaceColours.needsUpdate = true;
      this.surface.computeBoundingSphere();
    }
    const nj = this.data.joints.length;
    for (let j = 0; j < nj; ++j) {
      const o = 3 * (nj * f + j);
      this.m.makeTranslation(c.jpos[o], c.jpos[o + 1], c.jpos[o + 2]);
      this.joints.setMatrixAt(j, this.m);
      for (let k = 0; k < 3; ++k) {
        this.axisPositions.array[6 * j + k] = c.jpos[o + k] - this.axisLength * c.jaxes[o + k];
        this.axisPositions.array[6 * j + 3 + k] = c.jpos[o + k] + this.axisLength * c.jaxes[o + k];
      }
    }
    this.joints.instanceMatrix.needsUpdate = true;
    this.axisPositions.needsUpdate = true;
  }
}

/// The ground: a grid normal to "up" (against gravity; z in a spatial scene without it),
/// under the model; in a planar scene the x-y plane behind it.
function ground(THREE, data, box) {
  const L = box.size;
  const step = Math.pow(10, Math.floor(Math.log10(L / 4)));
  const size = Math.ceil(1.6 * L / step) * step;
  const grid = new THREE.GridHelper(size, Math.round(size / step), 0x9aa3ad, 0xd5d9de);
  const c = new THREE.Vector3(...box.centre);
  const up = upOf(THREE, data);
  grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), up);
  if (data.planar) {
    grid.position.set(c.x, c.y, box.lo[2] - 0.02 * L);
  } else {
    let low = Infinity;
    for (let k = 0; k < 8; ++k) {
      const p = new THREE.Vector3(k & 1 ? box.hi[0] : box.lo[0], k & 2 ? box.hi[1] : box.lo[1], k & 4 ? box.hi[2] : box.lo[2]);
      low = Math.min(low, p.sub(c).dot(up));
    }
    grid.position.copy(c).addScaledVector(up, low - 0.02 * L);
  }
  return grid;
}

function upOf(THREE, data) {
  if (data.planar) return new THREE.Vector3(0, 0, 1);
  const g = new THREE.Vector3(...data.gravity);
  return g.lengthSq() > 0 ? g.normalize().negate() : new THREE.Vector3(0, 0, 1);
}

// ----- camera controls: drag to turn, right-drag or shift-drag to pan, wheel to zoom --------

class Orbit {
  constructor(THREE, camera, dom, target, onChange) {
    this.THREE = THREE;
    this.camera = camera;
    this.target = target.clone();
    this.home = { position: camera.position.clone(), target: target.clone() };
    let last = null, mode = null;
    dom.addEventListener('contextmenu', (e) => e.preventDefault());
    dom.addEventListener('pointerdown', (e) => {
      last = [e.clientX, e.clientY];
      mode = e.button === 2 || e.shiftKey ? 'pan' : 'turn';
      dom.setPointerCapture(e.pointerId);
    });
    dom.addEventListener('pointerup', () => { last = null; });
    dom.addEventListener('pointermove', (e) => {
      if (!last) return;
      const dx = e.clientX - last[0], dy = e.clientY - last[1];
      last = [e.clientX, e.clientY];
      if (mode === 'turn') this.turn(-0.006 * dx, -0.006 * dy);
      else this.pan(dx, dy, dom.clientHeight);
      onChange();
    });
    dom.addEventListener('wheel', (e) => {
      e.preventDefault();
      const d = this.camera.position.clone().sub(this.target).multiplyScalar(Math.exp(0.001 * e.deltaY));
      this.camera.position.copy(this.target).add(d);
      onChange();
    }, { passive: false });
    dom.addEventListener('dblclick', () => { this.reset(); onChange(); });
  }
  turn(yaw, pitch) {
    const THREE = this.THREE;
    const d = this.camera.position.clone().sub(this.target);
    d.applyAxisAngle(this.camera.up, yaw);
    const right = new THREE.Vector3().crossVectors(this.camera.up, d).normalize();
    const turned = d.clone().applyAxisAngle(right, pitch);
    if (Math.abs(turned.clone().normalize().dot(this.camera.up)) < 0.995) d.copy(turned);
    this.camera.position.copy(this.target).add(d);
    this.camera.lookAt(this.target);
  }
  pan(dx, dy, height) {
    const THREE = this.THREE;
    const dist = this.camera.position.distanceTo(this.target);
    const k = 2 * dist * Math.tan((this.camera.fov * Math.PI) / 360) / height;
    const x = new THREE.Vector3().setFromMatrixColumn(this.camera.matrix, 0).multiplyScalar(-dx * k);
    const y = new THREE.Vector3().setFromMatrixColumn(this.camera.matrix, 1).multiplyScalar(dy * k);
    this.camera.position.add(x).add(y);
    this.target.add(x).add(y);
  }
  reset() {
    this.camera.position.copy(this.home.position);
    this.target.copy(this.home.target);
    this.camera.lookAt(this.target);
  }
}

// ----- plots of results columns with a cursor -----------------------------------------------

class Plot {
  constructor(parent, times, column) {
    this.times = times;
    this.column = column;
    const box = el('div', { class: 'plot' }, parent);
    this.label = el('div', { class: 'plot-label' }, box);
    this.canvas = el('canvas', {}, box);
    this.static = document.createElement('canvas');
    this.lo = Math.min(...column.values.filter(isFinite));
    this.hi = Math.max(...column.values.filter(isFinite));
    if (!(this.hi > this.lo)) { this.lo -= 1; this.hi += 1; }
  }
  layout() {
    const w = this.canvas.parentElement.clientWidth, h = 110;
    const r = window.devicePixelRatio || 1;
    for (const c of [this.canvas, this.static]) {
      c.width = w * r;
      c.height = h * r;
    }
    this.canvas.style.width = w + 'px';
    this.canvas.style.height = h + 'px';
    const g = this.static.getContext('2d');
    g.scale(r, r);
    g.fillStyle = '#fff';
    g.fillRect(0, 0, w, h);
    const t0 = this.times[0], t1 = this.times[this.times.length - 1];
    this.x = (t) => 58 + (w - 68) * (t1 > t0 ? (t - t0) / (t1 - t0) : 0);
    this.y = (v) => 8 + (h - 26) * (1 - (v - this.lo) / (this.hi - this.lo));
    g.strokeStyle = '#c8ccd2';
    g.strokeRect(58, 8, w - 68, h - 26);
    g.fillStyle = '#555';
    g.font = '11px sans-serif';
    g.textAlign = 'right';
    g.fillText(fmt(this.hi), 54, 14);
    g.fillText(fmt(this.lo), 54, h - 18);
    g.textAlign = 'left';
    g.fillText(fmt(t0), 58, h - 4);
    g.textAlign = 'right';
    g.fillText(fmt(t1) + ' s', w - 10, h - 4);
    g.strokeStyle = '#3b6ea8';
    g.lineWidth = 1.4;
    g.beginPath();
    let pen = false;
    this.column.values.forEach((v, k) => {
      if (!isFinite(v)) { pen = false; return; }
      const X = this.x(this.times[k]), Y = this.y(v);
      if (pen) g.lineTo(X, Y); else g.moveTo(X, Y);
      pen = true;
    });
    g.stroke();
  }
  cursor(t) {
    const g = this.canvas.getContext('2d');
    const r = window.devicePixelRatio || 1;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.drawImage(this.static, 0, 0);
    g.scale(r, r);
    g.strokeStyle = '#b8453f';
    g.beginPath();
    g.moveTo(this.x(t), 8);
    g.lineTo(this.x(t), this.canvas.height / r - 18);
    g.stroke();
    // the value at the cursor: the last sample at or before t
    let lo = 0, hi = this.times.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (this.times[mid] <= t) lo = mid; else hi = mid - 1;
    }
    const unit = this.column.unit ? ' ' + this.column.unit : '';
    this.label.textContent = `${this.column.name} = ${fmt(this.column.values[lo])}${unit}`;
  }
}

// ----- the page -----------------------------------------------------------------------------

async function main() {
  const data = readData();
  const THREE = await loadThree();
  document.title = `${data.title} - flexmbd view`;
  const app = el('div', { id: 'app' }, document.body);
  const header = el('header', {}, app);
  el('h1', { title: data.title }, header, data.title);
  el('span', { class: 'source' }, header, data.source);
  const main = el('div', { id: 'main' }, app);
  const view = el('div', { id: 'view' }, main);
  const canvas = el('canvas', { id: 'canvas' }, view);
  const note = el('div', { id: 'note' }, view);
  const legend = el('div', { id: 'legend' }, view);
  const side = el('aside', { id: 'side' }, main);
  const bar = el('div', { id: 'bar' }, app);
  const plotsBox = el('div', { id: 'plots' }, app);
  const status = el('pre', { id: 'flexmbd-status', hidden: '' }, app, '{}');

  // controls
  const play = el('button', { id: 'play', title: 'play / pause (space)' }, bar, 'Pause');
  const back = el('button', { title: 'one frame back' }, bar, '<');
  const forward = el('button', { title: 'one frame forward' }, bar, '>');
  const slider = el('input', { id: 'time', type: 'range', min: '0', step: '1' }, bar);
  const timeLabel = el('span', { id: 'time-label' }, bar);
  const field = (label) => { const f = el('label', {}, side, label); return f; };
  const clipSelect = el('select', { id: 'clip' }, field('animation '));
  data.clips.forEach((c, k) => el('option', { value: String(k) }, clipSelect, c.name));
  if (data.clips.length < 2) clipSelect.parentElement.hidden = true;
  const speedSelect = el('select', { id: 'speed' }, field('speed '));
  const colourSelect = el('select', { id: 'colour' }, field('colour '));
  el('option', { value: '-1' }, colourSelect, 'by body');
  data.quantities.forEach((q, k) => el('option', { value: String(k) }, colourSelect, `${q.name} (${q.unit})`));
  const scaleSelect = el('select', { id: 'scale' }, field('deformation x '));
  const bodyList = el('ul', { id: 'bodies' }, side);
  data.bodies.forEach((b, k) => {
    const li = el('li', {}, bodyList);
    const sw = el('span', { class: 'swatch' }, li);
    sw.style.background = '#' + BODY_COLOURS[k % BODY_COLOURS.length].toString(16).padStart(6, '0');
    li.appendChild(document.createTextNode(b));
  });
  el('p', { class: 'hint' }, side, 'Drag to turn, right-drag or shift-drag to pan, wheel to zoom, double-click to reset; space plays or pauses.');
  el('p', { class: 'hint' }, side, `${data.joints.length} joints (dark spheres, axes in red). three.js ${data.three}.`);

  // the three.js scene
  const box = extent(data);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(BACKGROUND);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f96, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  const up = upOf(THREE, data);
  sun.position.copy(up).multiplyScalar(3 * box.size).add(new THREE.Vector3(box.size, -box.size, 0));
  scene.add(sun);
  const model = new Model(THREE, data, box);
  scene.add(model.group);
  scene.add(ground(THREE, data, box));
  const camera = new THREE.PerspectiveCamera(40, 1, box.size / 1000, box.size * 100);
  camera.up.copy(up);
  const centre = new THREE.Vector3(...box.centre);
  if (data.planar) {
    camera.position.copy(centre).add(new THREE.Vector3(0, 0, 1.25 * box.size));
    camera.up.set(0, 1, 0);
  } else {
    const e1 = new THREE.Vector3(1, 0, 0);
    if (Math.abs(e1.dot(up)) > 0.9) e1.set(0, 1, 0);
    e1.addScaledVector(up, -e1.dot(up)).normalize();
    const e2 = new THREE.Vector3().crossVectors(up, e1);
    camera.position.copy(centre).addScaledVector(e1, 0.75 * box.size).addScaledVector(e2, -1.0 * box.size)
      .addScaledVector(up, 0.55 * box.size);
  }
  camera.lookAt(centre);
  let dirty = true;
  const orbit = new Orbit(THREE, camera, canvas, centre, () => { dirty = true; });

  // the state of the animation
  const state = { clip: 0, frame: 0, time: 0, playing: true, speed: 1, scale: 1, quantity: -1 };
  let plots = [];
  const clip = () => data.clips[state.clip];
  const duration = (c) => c.times[c.frames - 1] - c.times[0];

  function chooseClip(k) {
    state.clip = k;
    const c = clip();
    slider.max = String(c.frames - 1);
    // speed: the whole clip in about 8 s (a period of a mode in 1.5 s), then x2 steps
    const base = c.time_unit === 'period' ? 1 / 1.5 : (duration(c) || 1) / 8;
    speedSelect.textContent = '';
    for (const m of [0.125, 0.25, 0.5, 1, 2, 4]) {
      const v = base * m;
      const text = c.time_unit === 'period' ? `${fmt(v)} periods/s` : `${fmt(v)} x real time`;
      el('option', { value: String(v) }, speedSelect, text);
    }
    speedSelect.value = String(base);
    state.speed = base;
    // deformation scale: the largest elastic displacement drawn as 5 % of the model's size
    scaleSelect.textContent = '';
    let umax = 0;
    if (c.disp) for (let i = 0; i < c.disp.length; i += 3) umax = Math.max(umax, Math.hypot(c.disp[i], c.disp[i + 1], c.disp[i + 2]));
    // (at most x1000; mode shapes are drawn as flexmbd modes scaled them: x1)
    const auto = umax > 0 && c.time_unit !== 'period'
      ? Math.min(1000, Math.max(1, Math.pow(10, Math.round(Math.log10((0.05 * box.size) / umax))))) : 1;
    for (const s of [1, 10, 100, 1000, 10000]) el('option', { value: String(s) }, scaleSelect, String(s));
    if (![1, 10, 100, 1000, 10000].includes(auto)) el('option', { value: String(auto) }, scaleSelect, String(auto));
    scaleSelect.value = String(auto);
    state.scale = auto;
    scaleSelect.parentElement.hidden = !c.disp;
    setFrame(0);
  }

  function setFrame(f) {
    const c = clip();
    state.frame = Math.min(Math.max(f, 0), c.frames - 1);
    state.time = c.times[state.frame];
    dirty = true;
  }

  function frameAt(t) {
    const times = clip().times;
    let lo = 0, hi = times.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  function updateLegend() {
    const q = state.quantity >= 0 ? data.quantities[state.quantity] : null;
    legend.hidden = !q;
    if (q) {
      const stops = MAP.map((c, k) => `rgb(${c.map((x) => Math.round(255 * x)).join(',')}) ${(100 * k) / (MAP.length - 1)}%`);
      legend.innerHTML = '';
      el('div', { class: 'legend-title' }, legend, `${q.name} (${q.unit})`);
      const ramp = el('div', { class: 'ramp' }, legend);
      ramp.style.background = `linear-gradient(to right, ${stops.join(',')})`;
      const ends = el('div', { class: 'ends' }, legend);
      el('span', {}, ends, fmt(q.min));
      el('span', {}, ends, fmt(q.max));
    }
    note.textContent = clip().disp && state.scale !== 1 ? `elastic deformation drawn x${state.scale}` : '';
  }

  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    for (const p of plots) p.layout();
    dirty = true;
  }

  function draw() {
    const c = clip();
    model.show(c, state.frame, state.scale, state.quantity);
    renderer.render(scene, camera);
    slider.value = String(state.frame);
    const unit = c.time_unit === 'period' ? ' period' : ' s';
    timeLabel.textContent = `t = ${fmt(state.time)}${unit}  (frame ${state.frame + 1} of ${c.frames})`;
    for (const p of plots) p.cursor(state.clip === 0 ? state.time : data.plot_times[0]);
    dirty = false;
  }

  // events
  play.addEventListener('click', () => { state.playing = !state.playing; play.textContent = state.playing ? 'Pause' : 'Play'; });
  window.addEventListener('keydown', (e) => { if (e.code === 'Space' && e.target === document.body) { e.preventDefault(); play.click(); } });
  back.addEventListener('click', () => { state.playing = false; play.textContent = 'Play'; setFrame(state.frame - 1); });
  forward.addEventListener('click', () => { state.playing = false; play.textContent = 'Play'; setFrame(state.frame + 1); });
  slider.addEventListener('input', () => { state.playing = false; play.textContent = 'Play'; setFrame(Number(slider.value)); });
  clipSelect.addEventListener('change', () => { chooseClip(Number(clipSelect.value)); updateLegend(); });
  speedSelect.addEventListener('change', () => { state.speed = Number(speedSelect.value); });
  colourSelect.addEventListener('change', () => { state.quantity = Number(colourSelect.value); updateLegend(); dirty = true; });
  scaleSelect.addEventListener('change', () => { state.scale = Number(scaleSelect.value); updateLegend(); dirty = true; });
  window.addEventListener('resize', resize);

  if (data.plots.length && data.plot_times.length) {
    plots = data.plots.map((column) => new Plot(plotsBox, data.plot_times, column));
  } else {
    plotsBox.hidden = true;
  }
  const deflection = data.quantities.findIndex((q) => q.name === 'deflection');
  state.quantity = deflection;
  colourSelect.value = String(deflection);
  chooseClip(0);
  updateLegend();
  resize();
  draw();

  // what the browser test reads: the first frame is drawn, not blank; the time from the
  // start of the page's loading to its first frame
  const readyMs = Math.round(performance.now());
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
  const pixels = new Uint8Array(4 * w * h);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const ref = [(BACKGROUND >> 16) & 255, (BACKGROUND >> 8) & 255, BACKGROUND & 255];
  let drawn = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    if (Math.abs(pixels[i] - ref[0]) + Math.abs(pixels[i + 1] - ref[1]) + Math.abs(pixels[i + 2] - ref[2]) > 24) ++drawn;
  }
  const report = () => JSON.stringify({
    ok: errors.length === 0, frames: data.clips.reduce((n, c) => n + c.frames, 0),
    clips: data.clips.map((c) => c.frames), bodies: data.bodies.length, joints: data.joints.length,
    plots: plots.length, canvas: [w, h], drawn_pixels: drawn, ready_ms: readyMs, errors });
  status.textContent = report();

  let last = performance.now();
  function tick(now) {
    const dt = Math.min((now - last) / 1000, 0.1);
    last = now;
    if (state.playing) {
      const c = clip();
      const span = duration(c);
      let t = state.time + dt * state.speed;
      if (c.time_unit === 'period') t = t % 1;
      else if (t > c.times[0] + span) t = c.times[0];
      state.time = t;
      state.frame = frameAt(t);
      dirty = true;
    }
    if (dirty) draw();
    if (errors.length) status.textContent = report();
    requestAnimationFrame(tick);
  }
  requestAnimationFrame(tick);
}

main().catch((e) => {
  errors.push(String(e && e.stack ? e.stack : e));
  const s = document.getElementById('flexmbd-status') || el('pre', { id: 'flexmbd-status' }, document.body);
  s.textContent = JSON.stringify({ ok: false, errors });
});
