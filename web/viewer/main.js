// impinge view's page (issue 79): both bones in three.js, every pose detected by the server (impinge.view), the
// per-vertex values coloured. One colour-buffer update and one draw per frame; the femur moves by its matrix
// (no mesh rebuild). window.__impinge is the test hook (tests/viewer/): the last frame's values and colours.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const token = new URLSearchParams(location.search).get('token') || '';
const $ = (id) => document.getElementById(id);
const withToken = (path) => path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);

function showError(message) {
  $('error').textContent = message;
}

async function fetchChecked(path) {
  const r = await fetch(withToken(path));
  if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
  return r;
}

// A bone from /api/mesh/NAME: uint32 n, uint32 m, float32 V (n x 3), uint32 F (m x 3).
async function fetchMesh(name) {
  const buf = await (await fetchChecked(`/api/mesh/${name}`)).arrayBuffer();
  const [n, m] = new Uint32Array(buf, 0, 2);
  const V = new Float32Array(buf, 8, n * 3);
  const F = new Uint32Array(buf, 8 + n * 12, m * 3);
  return { V, F, n, m };
}

// One frame from the server (impinge.view's module docstring gives the layout).
function decodeFrame(buf, nf, np) {
  const hlen = new DataView(buf).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, hlen)));
  let off = 4 + hlen + ((4 - (hlen % 4)) % 4);
  const f32 = (n) => { const a = new Float32Array(buf, off, n); off += n * 4; return a; };
  const u8 = (n) => { const a = new Uint8Array(buf, off, n); off += n + ((4 - (n % 4)) % 4); return a; };
  const femurGap = f32(nf), pelvisGap = f32(np), femurDistance = f32(nf), pelvisDistance = f32(np);
  const femurLevel = u8(nf), pelvisLevel = u8(np);
  return { ...header, femur: { gap: femurGap, distance: femurDistance, level: femurLevel },
           pelvis: { gap: pelvisGap, distance: pelvisDistance, level: pelvisLevel } };
}

// A diverging ramp for a length in mm: purple (deep overlap) - red - orange - yellow (touching) - green/blue (apart).
const RAMP = [[-2, [140, 0, 200]], [-0.5, [220, 20, 20]], [0, [255, 140, 0]], [1, [255, 230, 0]],
              [3, [120, 200, 120]], [6, [60, 120, 220]]];
function rampColour(x) {
  if (x <= RAMP[0][0]) return RAMP[0][1];
  for (let k = 1; k < RAMP.length; ++k) {
    if (x <= RAMP[k][0]) {
      const [a, ca] = RAMP[k - 1], [b, cb] = RAMP[k];
      const w = (x - a) / (b - a);
      return [0, 1, 2].map((i) => ca[i] + w * (cb[i] - ca[i]));
    }
  }
  return RAMP[RAMP.length - 1][1];
}

async function start() {
  const scene = await (await fetchChecked('/api/scene')).json();
  const [femurMesh, pelvisMesh] = await Promise.all([fetchMesh('femur'), fetchMesh('pelvis')]);
  $('subject').textContent = `${scene.side} hip, ${scene.femur_triangles + scene.pelvis_triangles} triangles; ` +
      `joint centre ${scene.joint_centre}; neutral ${scene.neutral}; impinge ${scene.impinge_version}`;
  if (scene.warnings.length) $('warnings').textContent = 'Warnings: ' + scene.warnings.join('; ');

  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  $('view').prepend(renderer.domElement);
  const view = new THREE.Scene();
  view.background = new THREE.Color(0xf4f4f2);
  const camera = new THREE.PerspectiveCamera(35, 1, 1, 5000);
  view.add(camera);
  view.add(new THREE.HemisphereLight(0xffffff, 0x666666, 1.6));
  const lamp = new THREE.DirectionalLight(0xffffff, 1.4);
  lamp.position.set(0.3, 0.5, 1);
  camera.add(lamp);
  const controls = new OrbitControls(camera, renderer.domElement);
  const centre = new THREE.Vector3(...scene.head_centre_mm);
  controls.target.copy(centre);

  function body(m, name) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(m.V, 3));
    g.setIndex(new THREE.BufferAttribute(m.F, 1));
    g.computeVertexNormals();
    const colour = new Uint8Array(m.n * 3).fill(200);
    g.setAttribute('color', new THREE.BufferAttribute(colour, 3, true));
    const mat = new THREE.MeshPhongMaterial({ vertexColors: true, side: THREE.DoubleSide, shininess: 20 });
    const mesh = new THREE.Mesh(g, mat);
    mesh.name = name;
    view.add(mesh);
    return { mesh, geometry: g, colour, full: g.index, n: m.n };
  }
  const femur = body(femurMesh, 'femur'), pelvis = body(pelvisMesh, 'pelvis');
  femur.mesh.matrixAutoUpdate = false;

  // The pelvis cropped to the acetabular region (thesis Figure 62): its triangles within this of the head centre.
  const cropRadius = (scene.head_radius_mm || 25) + 20;
  const cropped = (() => {
    const V = pelvisMesh.V, F = pelvisMesh.F, keep = [];
    const r2 = cropRadius * cropRadius;
    for (let t = 0; t < pelvisMesh.m; ++t) {
      for (let c = 0; c < 3; ++c) {
        const i = F[3 * t + c] * 3;
        const dx = V[i] - centre.x, dy = V[i + 1] - centre.y, dz = V[i + 2] - centre.z;
        if (dx * dx + dy * dy + dz * dz < r2) { keep.push(F[3 * t], F[3 * t + 1], F[3 * t + 2]); break; }
      }
    }
    return new THREE.BufferAttribute(new Uint32Array(keep), 1);
  })();

  // The whole pelvis' reach from the head centre (the camera's distance for the uncropped view).
  const wholeRadius = (() => {
    let r2 = 0;
    const V = pelvisMesh.V;
    for (let i = 0; i < V.length; i += 3) {
      const dx = V[i] - centre.x, dy = V[i + 1] - centre.y, dz = V[i + 2] - centre.z;
      r2 = Math.max(r2, dx * dx + dy * dy + dz * dz);
    }
    return Math.sqrt(r2);
  })();

  // Anatomical axes (input frame) for the view presets: the pelvic frame's, else the scan's (RAS or LPS).
  const lps = scene.input_frame === 'LPS';
  const axes = scene.axes || { x: lps ? [0, -1, 0] : [0, 1, 0], y: [0, 0, 1], z: lps ? [-1, 0, 0] : [1, 0, 0] };
  const anterior = new THREE.Vector3(...axes.x), superior = new THREE.Vector3(...axes.y);
  const right = new THREE.Vector3(...axes.z);
  const lateral = scene.side === 'left' ? right.clone().negate() : right.clone();
  const presets = {
    anterior: [anterior, superior], lateral: [lateral, superior], medial: [lateral.clone().negate(), superior],
    superior: [superior, anterior], oblique: [anterior.clone().add(lateral).add(superior.clone().multiplyScalar(0.6)),
                                              superior],
  };
  let lastView = 'anterior';
  function setView(name) {
    lastView = name;
    const [dir, up] = presets[name];
    const d = dir.clone().normalize();
    const dist = $('crop').checked ? 5.5 * cropRadius : 2.8 * wholeRadius;
    camera.position.copy(centre).addScaledVector(d, dist);
    camera.up.copy(up);
    controls.target.copy(centre);
    camera.lookAt(centre);
    controls.update();
    requestDraw();
  }
  for (const name of Object.keys(presets)) {
    const b = document.createElement('button');
    b.textContent = name;
    b.onclick = () => setView(name);
    $('views').append(b);
  }

  // Colours: the library's levels (the PLY files' colours) or a ramp of the chosen length.
  const palette = scene.palette;
  let last = null;
  function colourBody(b, values, bone) {
    const mode = $('colour').value, c = b.colour;
    const pal = palette[bone], untested = palette.untested;
    for (let i = 0; i < b.n; ++i) {
      let rgb;
      if (mode === 'levels') {
        const k = values.level[i];
        rgb = k === 255 ? untested : pal[k];
      } else {
        const x = values[mode][i];
        rgb = Number.isNaN(x) ? untested : rampColour(x);
      }
      c[3 * i] = rgb[0]; c[3 * i + 1] = rgb[1]; c[3 * i + 2] = rgb[2];
    }
    b.geometry.attributes.color.needsUpdate = true;
  }
  function legend() {
    const mode = $('colour').value;
    if (mode === 'levels') {
      const t = scene.levels_thresholds_mm;
      const stops = palette.pelvis.map((c, k) => `rgb(${c}) ${100 * k / palette.pelvis.length}% ${100 * (k + 1) / palette.pelvis.length}%`);
      $('legend').style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      const mm = (x) => Number(x.toFixed(2));
      $('legend-labels').innerHTML = ['&gt;' + mm(t[0])].concat(t.slice(1).map((x, k) => `${mm(t[k])}-${mm(x)}`))
          .concat(['&le;' + mm(t[t.length - 1])]).map((s) => `<span>${s}</span>`).join('') + '<span>mm</span>';
    } else {
      const lo = RAMP[0][0], hi = RAMP[RAMP.length - 1][0];
      const stops = RAMP.map(([x, c]) => `rgb(${c}) ${100 * (x - lo) / (hi - lo)}%`);
      $('legend').style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      $('legend-labels').innerHTML = RAMP.map(([x]) => `<span>${x}</span>`).join('') + '<span>mm</span>';
    }
  }
  function recolour() {
    if (!last) return;
    colourBody(femur, last.femur, 'femur');
    colourBody(pelvis, last.pelvis, 'pelvis');
    legend();
    requestDraw();
  }

  function display() {
    const mode = $('display').value;
    for (const b of [femur, pelvis]) {
      const m = b.mesh.material;
      m.wireframe = mode === 'lines';
      m.transparent = mode === 'blending';
      m.opacity = mode === 'blending' ? 0.45 : 1;
      m.depthWrite = mode !== 'blending';
      m.needsUpdate = true;
    }
    femur.mesh.visible = $('show-femur').checked;
    pelvis.mesh.visible = $('show-pelvis').checked;
    pelvis.geometry.setIndex($('crop').checked ? cropped : pelvis.full);
    requestDraw();
  }

  function showNumbers(f) {
    const s = f.summary, fmt = (x, d = 2) => (x === null || x === undefined || Number.isNaN(x) ? 'n/a' : x.toFixed(d));
    $('numbers').innerHTML = [
      ['least distance', fmt(s.least_distance_mm), 'mm'], ['least radial gap', fmt(s.least_gap_mm), 'mm'],
      ['contact area (pelvis, overlapping)', fmt(s.contact_area_mm2, 1), 'mm²'],
      ['detection', fmt(f.ms, 1), 'ms'],
    ].map(([k, v, u]) => `<tr><td>${k}</td><td class="v">${v}</td><td>${u}</td></tr>`).join('');
  }

  function applyFrame(f) {
    last = f;
    const R = f.R, t = f.t, c = centre;
    // posed = R (v - c) + c + t
    const m = new THREE.Matrix4().set(R[0], R[1], R[2], 0, R[3], R[4], R[5], 0, R[6], R[7], R[8], 0, 0, 0, 0, 1);
    const shift = new THREE.Vector3(c.x, c.y, c.z).sub(new THREE.Vector3(c.x, c.y, c.z).applyMatrix4(m));
    m.setPosition(shift.x + t[0], shift.y + t[1], shift.z + t[2]);
    femur.mesh.matrix.copy(m);
    femur.mesh.matrixWorldNeedsUpdate = true;
    recolour();
    showNumbers(f);
    $('status').textContent = `flexion ${f.pose[0]}, adduction ${f.pose[1]}, internal rotation ${f.pose[2]} deg`;
    hook.frame = f;
    for (const w of hook.waiting.splice(0)) if (w.id <= f.id) w.resolve(f); else hook.waiting.push(w);
  }

  // The WebSocket: the newest pose only (the server drops older pending ones too).
  const ws = new WebSocket(withToken(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`));
  ws.binaryType = 'arraybuffer';
  let nextId = 1;
  ws.onmessage = (e) => {
    if (typeof e.data === 'string') {
      const m = JSON.parse(e.data);
      if (m.type === 'error') showError(m.message);
      return;
    }
    showError('');
    applyFrame(decodeFrame(e.data, femur.n, pelvis.n));
  };
  ws.onclose = () => { $('status').textContent = 'the server has stopped'; };
  const opened = new Promise((resolve) => { ws.onopen = resolve; });

  function sendPose(pose) {
    const id = nextId++;
    ws.send(JSON.stringify({ type: 'pose', id, pose }));
    return id;
  }
  const names = ['flexion', 'adduction', 'internal_rotation'];
  function currentPose() { return names.map((n) => Number($(n + '-n').value)); }
  for (const n of names) {
    $(n).addEventListener('input', () => { $(n + '-n').value = $(n).value; sendPose(currentPose()); });
    $(n + '-n').addEventListener('change', () => { $(n).value = $(n + '-n').value; sendPose(currentPose()); });
  }
  $('neutral').onclick = () => { for (const n of names) { $(n).value = 0; $(n + '-n').value = 0; } sendPose([0, 0, 0]); };
  $('colour').onchange = recolour;
  for (const id of ['display', 'show-femur', 'show-pelvis']) $(id).onchange = display;
  $('crop').onchange = () => { display(); setView(lastView); };

  let drawPending = false;
  function requestDraw() {
    if (drawPending) return;
    drawPending = true;
    requestAnimationFrame(() => {
      drawPending = false;
      const el = $('view');
      const w = el.clientWidth, h = el.clientHeight;
      if (renderer.domElement.width !== Math.floor(w * renderer.getPixelRatio())) {
        renderer.setSize(w, h, false);
        camera.aspect = w / h;
        camera.updateProjectionMatrix();
      }
      const t0 = performance.now();
      renderer.render(view, camera);
      hook.drawMs = performance.now() - t0;
      hook.draws += 1;
    });
  }
  controls.addEventListener('change', requestDraw);
  window.addEventListener('resize', requestDraw);

  // The test hook: set a pose and wait for its frame; read what was drawn.
  const hook = window.__impinge;
  hook.scene = scene;
  hook.setPose = (f, a, r) => {
    for (const [n, v] of [['flexion', f], ['adduction', a], ['internal_rotation', r]]) { $(n).value = v; $(n + '-n').value = v; }
    const id = sendPose([f, a, r]);
    return new Promise((resolve) => hook.waiting.push({ id, resolve }));
  };
  hook.colours = () => ({ femur: Array.from(femur.colour), pelvis: Array.from(pelvis.colour) });
  hook.values = (bone, what) => Array.from(hook.frame[bone][what]);

  display();
  setView('anterior');
  legend();
  await opened;
  await hook.setPose(0, 0, 0);
  hook.ready = true;
}

window.__impinge = { ready: false, waiting: [], frame: null, draws: 0, drawMs: NaN, error: null };
start().catch((e) => { window.__impinge.error = String(e); showError(String(e)); });
