// stripemux live view: the feed of `stripemux view` / `stripemux scan --view` over a WebSocket
// (docs/live-view.md). Binary messages share a 24-byte little-endian header (messages.hpp):
//   u8 kind, u8 camera, u16 width, u16 height, u16 step, u32 seq, u32 sizeA, u32 sizeB, u32 aux
'use strict';

const KIND_DEPTH = 1;
const KIND_RAYS = 2;
const KIND_MODEL = 3;
const HEADER_BYTES = 24;
const CLOUD_STEP = 2;  // every second pixel of each camera goes to the point cloud

// What tests and users can read from the console.
const smxView = {
  framesDrawn: 0, lastSeq: 0, session: null, status: null, webgl: false, errors: [],
  depthRange: [0, 0], messages: [],
};
window.smxView = smxView;
// The newest depth a camera's panel shows at a pixel, in metres (0: none).
smxView.depthAt = (camera, x, y) => {
  const p = panels[camera];
  return p ? p.depth[y * p.width + x] * smxView.session.device.depth_unit_m : 0;
};

const $ = (id) => document.getElementById(id);

// RVL as stripemux codes it (docs/protocol.md): runs of zeros and of values, each value the
// zigzag difference to the previous one, every number a code of 3-bit groups in 4-bit nibbles.
function rvlDecode(bytes, out) {
  let nibble = 0;
  const total = bytes.length * 2;
  const code = () => {
    let value = 0;
    let scale = 1;
    for (let i = 0; i < 11; ++i) {
      if (nibble >= total) throw new Error('RVL data ends early');
      const b = bytes[nibble >> 1];
      const n = (nibble & 1) === 0 ? b >> 4 : b & 15;
      ++nibble;
      value += (n & 7) * scale;
      scale *= 8;
      if ((n & 8) === 0) return value;
    }
    throw new Error('RVL code too long');
  };
  let filled = 0;
  let previous = 0;
  while (filled < out.length) {
    const zeros = code();
    const values = code();
    if (zeros + values > out.length - filled || zeros + values === 0) {
      throw new Error('RVL run past the image');
    }
    out.fill(0, filled, filled + zeros);
    filled += zeros;
    for (let i = 0; i < values; ++i) {
      const z = code();
      previous += (z & 1) ? -((z + 1) / 2) : z / 2;
      out[filled++] = previous;
    }
  }
}

// Turbo-like colour ramp from near (red) to far (blue); index 0 … 255.
const RAMP = (() => {
  const ramp = new Uint8Array(256 * 3);
  for (let i = 0; i < 256; ++i) {
    const t = 1 - i / 255;
    const r = 34.61 + t * (1172.33 - t * (10793.56 - t * (33300.12 - t * (38394.49 - t * 14825.05))));
    const g = 23.31 + t * (557.33 + t * (1225.33 - t * (3574.96 - t * (1073.77 + t * 707.56))));
    const b = 27.2 + t * (3211.1 - t * (15327.97 - t * (27814 - t * (22569.18 - t * 6838.66))));
    ramp.set([r, g, b].map((v) => Math.max(0, Math.min(255, v))), i * 3);
  }
  return ramp;
})();

// The ramp and a grey scale as canvas pixels (RGBA bytes, little-endian words).
const RAMP32 = (() => {
  const out = new Uint32Array(256);
  for (let i = 0; i < 256; ++i) {
    out[i] = (255 << 24 | RAMP[i * 3 + 2] << 16 | RAMP[i * 3 + 1] << 8 | RAMP[i * 3]) >>> 0;
  }
  return out;
})();
const GREY32 = Uint32Array.from({ length: 256 }, (_, v) => (255 << 24 | v << 16 | v << 8 | v) >>> 0);
const BLACK32 = 0xff000000;

function header(view) {
  return {
    kind: view.getUint8(0), camera: view.getUint8(1), width: view.getUint16(2, true),
    height: view.getUint16(4, true), step: view.getUint16(6, true), seq: view.getUint32(8, true),
    sizeA: view.getUint32(12, true), sizeB: view.getUint32(16, true), aux: view.getUint32(20, true),
  };
}

// The 2nd and 98th percentiles of the non-zero depths (a histogram of every 4th pixel).
function depthRange(depth) {
  const bins = new Uint32Array(1024);
  let count = 0;
  for (let i = 0; i < depth.length; i += 4) {
    if (depth[i] !== 0) { ++bins[depth[i] >> 6]; ++count; }
  }
  if (count === 0) return null;
  const at = (q) => {
    let seen = 0;
    for (let b = 0; b < bins.length; ++b) {
      seen += bins[b];
      if (seen >= q * count) return b << 6;
    }
    return 65535;
  };
  const near = at(0.02);
  return [near, Math.max(near + 64, at(0.98) + 64)];
}

class CameraPanel {
  constructor(index, info) {
    this.index = index;
    this.width = info.width;
    this.height = info.height;
    const box = document.createElement('div');
    box.className = 'camera';
    box.innerHTML = `<h2>${info.id}: depth</h2>`;
    this.depthCanvas = this.canvas(box, 'depth', `depth-cam${index}`);
    this.legend = document.createElement('div');
    this.legend.className = 'legend';
    box.appendChild(this.legend);
    const h = document.createElement('h2');
    h.textContent = `${info.id}: confidence`;
    box.appendChild(h);
    this.confidenceCanvas = this.canvas(box, 'confidence', `confidence-cam${index}`);
    this.confidenceCanvas.width = this.width / 2;
    this.confidenceCanvas.height = this.height / 2;
    $('cameras').appendChild(box);
    this.depth = new Uint16Array(this.width * this.height);
    this.confidence = null;
    this.range = null;
    this.rays = null;
    this.pose = info;
  }

  canvas(box, cls, id) {
    const c = document.createElement('canvas');
    c.className = cls;
    c.id = id;
    c.width = this.width;
    c.height = this.height;
    box.appendChild(c);
    return c;
  }

  draw(h, bytes, unitM) {
    rvlDecode(bytes.subarray(HEADER_BYTES, HEADER_BYTES + h.sizeA), this.depth);
    const range = depthRange(this.depth);
    if (range) {
      // Smoothed so that the colours do not flicker from frame to frame.
      this.range = this.range
        ? this.range.map((v, i) => 0.8 * v + 0.2 * range[i]) : range;
    }
    const [near, far] = this.range || [0, 1];
    const image = new ImageData(this.width, this.height);
    const px = new Uint32Array(image.data.buffer);
    const scale = 255 / Math.max(1, far - near);
    for (let i = 0; i < this.depth.length; ++i) {
      const d = this.depth[i];
      px[i] = d === 0 ? BLACK32 : RAMP32[Math.max(0, Math.min(255, Math.round((d - near) * scale)))];
    }
    this.depthCanvas.getContext('2d').putImageData(image, 0, 0);
    smxView.depthRange = [near * unitM, far * unitM];
    this.legend.textContent = `red ${(near * unitM).toFixed(3)} m … blue ${(far * unitM).toFixed(3)} m`;
    if (h.sizeB === 0) {
      this.confidenceCanvas.getContext('2d').clearRect(0, 0, this.confidenceCanvas.width,
                                                        this.confidenceCanvas.height);
    } else if (h.step > 0) {
      const cw = Math.floor(this.width / h.step);
      const ch = Math.floor(this.height / h.step);
      if (!this.confidence || this.confidence.length !== cw * ch) {
        this.confidence = new Uint8Array(cw * ch);
        this.confidenceCanvas.width = cw;
        this.confidenceCanvas.height = ch;
      }
      rvlDecode(bytes.subarray(HEADER_BYTES + h.sizeA, HEADER_BYTES + h.sizeA + h.sizeB),
                this.confidence);
      const c = new ImageData(cw, ch);
      const cpx = new Uint32Array(c.data.buffer);
      for (let i = 0; i < this.confidence.length; ++i) cpx[i] = GREY32[this.confidence[i]];
      this.confidenceCanvas.getContext('2d').putImageData(c, 0, 0);
    }
  }
}

// three.js scene: the live cloud of every camera and, during a scan, the model so far.
class Cloud {
  constructor(element, cameras) {
    this.renderer = new THREE.WebGLRenderer({ antialias: false });
    this.renderer.setSize(element.clientWidth, element.clientHeight);
    element.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(50, element.clientWidth / element.clientHeight,
                                              0.01, 20);
    this.camera.up.set(0, -1, 0);  // the rig's y points down
    this.camera.position.set(0, 0, 0);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0, 0, 1);
    this.controls.update();
    this.live = cameras.map((c) => this.points(Math.ceil(c.width / CLOUD_STEP) *
                                               Math.ceil(c.height / CLOUD_STEP), 0.002));
    this.model = null;
    this.aimed = false;
    // Drawn only when something changed: a software renderer must not take the page's time.
    this.dirty = true;
    this.controls.addEventListener('change', () => { this.dirty = true; });
    const loop = () => {
      if (this.dirty) {
        this.dirty = false;
        this.renderer.render(this.scene, this.camera);
      }
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }

  points(count, size) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(count * 3), 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(count * 3), 3));
    geometry.setDrawRange(0, 0);
    const p = new THREE.Points(geometry, new THREE.PointsMaterial({ size, vertexColors: true }));
    p.frustumCulled = false;
    this.scene.add(p);
    return p;
  }

  // One camera's depth as points in the rig's frame: X = Rᵀ (z · ray − t).
  updateCamera(panel, unitM) {
    if (!panel.rays) return;
    const pts = this.live[panel.index];
    const pos = pts.geometry.attributes.position.array;
    const col = pts.geometry.attributes.color.array;
    const R = panel.pose.r;
    const t = panel.pose.t;
    const [near, far] = panel.range || [0, 1];
    let n = 0;
    let sum = 0;
    const cols = Math.ceil(panel.width / CLOUD_STEP);
    for (let y = 0, row = 0; y < panel.height; y += CLOUD_STEP, ++row) {
      for (let x = 0, c = 0; x < panel.width; x += CLOUD_STEP, ++c) {
        const d = panel.depth[y * panel.width + x];
        if (d === 0) continue;
        const z = d * unitM;
        const r = (row * cols + c) * 2;
        if (Number.isNaN(panel.rays[r])) continue;
        const cx = z * panel.rays[r] - t[0];
        const cy = z * panel.rays[r + 1] - t[1];
        const cz = z - t[2];
        pos[n * 3] = R[0] * cx + R[3] * cy + R[6] * cz;
        pos[n * 3 + 1] = R[1] * cx + R[4] * cy + R[7] * cz;
        pos[n * 3 + 2] = R[2] * cx + R[5] * cy + R[8] * cz;
        sum += pos[n * 3 + 2];
        const k = Math.max(0, Math.min(255, Math.round((d - near) * 255 / Math.max(1, far - near)))) * 3;
        col[n * 3] = RAMP[k] / 255; col[n * 3 + 1] = RAMP[k + 1] / 255; col[n * 3 + 2] = RAMP[k + 2] / 255;
        ++n;
      }
    }
    pts.geometry.setDrawRange(0, n);
    pts.geometry.attributes.position.needsUpdate = true;
    pts.geometry.attributes.color.needsUpdate = true;
    if (!this.aimed && n > 100) {
      this.controls.target.set(0, 0, sum / n);
      this.controls.update();
      this.aimed = true;
    }
    this.dirty = true;
  }

  updateModel(h, buffer) {
    const count = h.sizeA;
    if (this.model) {
      this.scene.remove(this.model);
      this.model.geometry.dispose();
    }
    this.model = this.points(count, 0.0025);
    const pos = this.model.geometry.attributes.position.array;
    pos.set(new Float32Array(buffer, HEADER_BYTES, count * 3));
    const rgb = new Uint8Array(buffer, HEADER_BYTES + count * 12, count * 3);
    const col = this.model.geometry.attributes.color.array;
    for (let i = 0; i < rgb.length; ++i) col[i] = rgb[i] / 255;
    this.model.geometry.setDrawRange(0, count);
    this.dirty = true;
  }
}

let socket = null;
let panels = [];
let cloud = null;

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

function control(action, value) {
  const message = { type: 'control', action };
  if (value) message.value = value;
  send(message);
  $('message').textContent = `${action}${value ? ' ' + value : ''} sent`;
}

function rows(table, entries) {
  table.innerHTML = '';
  for (const [name, value, cls] of entries) {
    const tr = table.insertRow();
    tr.insertCell().textContent = name;
    const td = tr.insertCell();
    td.textContent = value;
    if (cls) td.className = cls;
  }
}

const fixed = (v, d) => (typeof v === 'number' ? v.toFixed(d) : '–');

function onSession(s) {
  smxView.session = s;
  $('device').textContent = `${s.device.address}: ${s.device.board}, firmware ` +
    `${s.device.firmware}, ${s.device.cameras} camera(s), ${s.device.projectors} projector(s), ` +
    `${s.device.width}×${s.device.height} at ${s.device.fps} fps`;
  $('cameras').innerHTML = '';
  panels = s.cameras.map((c, i) => new CameraPanel(i, c));
  const select = $('preset');
  select.innerHTML = '';
  for (const p of s.presets || []) {
    const o = document.createElement('option');
    o.value = p; o.textContent = p;
    select.appendChild(o);
  }
  if (typeof THREE === 'undefined') {
    $('cloud-note').textContent = 'No 3D view: three.js is not installed (Debian package libjs-three).';
    return;
  }
  try {
    $('cloud').innerHTML = '';
    cloud = new Cloud($('cloud'), s.cameras);
    smxView.webgl = true;
  } catch (e) {
    cloud = null;
    $('cloud-note').textContent = `No 3D view: ${e.message}`;
  }
}

function onStatus(s) {
  smxView.status = s;
  const d = s.device || {};
  rows($('counters'), [
    ['streaming', s.streaming ? 'yes' : 'no', s.streaming ? 'good' : 'weak'],
    ['uptime', `${fixed((d.uptime_ms || 0) / 1000, 0)} s`],
    ['captured', d.frames_captured], ['decoded', d.frames_decoded], ['sent', d.frames_sent],
    ['dropped (host slow)', d.frames_dropped], ['capture errors', d.capture_errors],
    ['decode', `${fixed((d.decode_time_us_mean || 0) / 1000, 1)} ms`],
  ]);
  const h = s.host || {};
  const p = s.page || {};
  rows($('page'), [
    ['received', `${fixed(h.received_per_s, 1)} fps`],
    ['drawn', `${fixed(p.drawn_per_s, 1)} fps`],
    ['received → drawn', `${fixed(p.latency_ms && p.latency_ms.mean, 1)} ms mean, ` +
      `${fixed(p.latency_ms && p.latency_ms.p95, 1)} p95`],
    ['capture → host', `${fixed(h.capture_to_host_ms, 1)} ms`],
    ['depth on the wire', `${fixed(h.page_kib_per_frame, 0)} KiB/frame`],
    ['host tool CPU', `${fixed(h.cpu_percent, 0)} %`],
  ]);
  const sc = s.scan;
  if (sc) {
    const entries = [['mode', sc.mode], ['state', sc.state, sc.state === 'LOST' ? 'bad' : 'good']];
    if (sc.views !== undefined) entries.push(['views', `${sc.views_done} / ${sc.views}`]);
    if (sc.captures !== undefined) entries.push(['captures', `${sc.captures}, ${sc.fused} fused, ${sc.lost} lost`]);
    if (sc.quality !== undefined) entries.push(['tracking quality', fixed(sc.quality, 2), sc.quality >= 0.5 ? 'good' : 'weak']);
    entries.push(['coverage', `${fixed(sc.coverage_pct, 0)} % of sides seen`]);
    entries.push(['model points', sc.model_points]);
    if (sc.out) entries.push(['output', sc.out]);
    rows($('scan'), entries);
  } else {
    rows($('scan'), [['mode', 'no scan running']]);
  }
  if (s.settings) {
    rows($('settings'), Object.entries(s.settings).map(
      ([k, v]) => [k, typeof v === 'string' ? v : JSON.stringify(v)]));
  }
  if (s.message) $('message').textContent = s.message;
  for (const [id, ok] of Object.entries(s.controls || {})) {
    if ($(id)) $(id).disabled = !ok;
  }
}

function onBinary(buffer) {
  const bytes = new Uint8Array(buffer);
  if (bytes.length < HEADER_BYTES) return;
  const h = header(new DataView(buffer));
  if (h.kind === KIND_DEPTH) {
    const began = performance.now();
    const panel = panels[h.camera];
    if (panel && h.width === panel.width && h.height === panel.height) {
      const unitM = smxView.session.device.depth_unit_m;
      panel.draw(h, bytes, unitM);
      if (cloud) cloud.updateCamera(panel, unitM);
      ++smxView.framesDrawn;
      smxView.lastSeq = h.seq;
      smxView.lastBytes = [h.sizeA, h.sizeB];
      smxView.drawMs = performance.now() - began;
    }
    send({ type: 'drawn', seq: h.seq });
  } else if (h.kind === KIND_RAYS) {
    const panel = panels[h.camera];
    if (panel) panel.rays = new Float32Array(buffer.slice(HEADER_BYTES, HEADER_BYTES + h.sizeA));
  } else if (h.kind === KIND_MODEL && cloud) {
    cloud.updateModel(h, buffer);
  }
}

function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => { $('link').textContent = 'live'; $('link').className = 'good'; };
  socket.onclose = () => {
    $('link').textContent = 'offline'; $('link').className = 'bad';
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    try {
      if (typeof event.data !== 'string') { onBinary(event.data); return; }
      const m = JSON.parse(event.data);
      if (m.type === 'session') onSession(m);
      else if (m.type === 'status') onStatus(m);
      else { smxView.messages.push(m); $('message').textContent = `${m.type}: ${m.message}`; }
    } catch (e) {
      smxView.errors.push(String(e));
      $('message').textContent = `page error: ${e.message}`;
    }
  };
}

$('start').onclick = () => control('start');
$('stop').onclick = () => control('stop');
$('apply-preset').onclick = () => control('preset', $('preset').value);
$('set-config').onclick = () => { if ($('config').value) control('config', $('config').value); };
$('scan-turntable').onclick = () => control('scan', 'turntable');
$('scan-handheld').onclick = () => control('scan', 'handheld');
$('stop-scan').onclick = () => control('stop-scan');
connect();
