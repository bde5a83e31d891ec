// impinge view's page (issue 79): both bones in three.js, every pose detected by the server (impinge.view), the
// per-vertex values coloured. One colour-buffer update and one draw per frame; the femur moves by its matrix
// (no mesh rebuild). window.__impinge is the test hook (tests/viewer/): the last frame's values and colours.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const token = new URLSearchParams(location.search).get('token') || '';
const $ = (id) => document.getElementById(id);
const withToken = (path) => path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);

let errorShownAt = 0;
function showError(message) {
  $('error').textContent = message;
  errorShownAt = message ? performance.now() : 0;
}
const escapeHtml = (t) => String(t).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);

async function fetchChecked(path) {
  const r = await fetch(withToken(path));
  if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
  return r;
}

// An exported file (impinge view --export) carries the server's answers inside it: no server, no network.
const stored = window.__IMPINGE_EXPORT__ || null;
const fromBase64 = (t) => Uint8Array.from(atob(t), (c) => c.charCodeAt(0)).buffer;
async function getJSON(path) {
  if (!stored) return (await fetchChecked(path)).json();
  if (!(path in stored.json)) throw new Error(`${path}: not in this exported file`);
  return stored.json[path];
}
async function getBuffer(path) {
  if (!stored) return (await fetchChecked(path)).arrayBuffer();
  return fromBase64(stored.buffers[path]);
}

// A bone from /api/mesh/NAME: uint32 n, uint32 m, float32 V (n x 3), uint32 F (m x 3).
async function fetchMesh(name) {
  const buf = await getBuffer(`/api/mesh/${name}`);
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
  const scene = await getJSON('/api/scene');
  if (stored) $('stored').textContent = stored.note;
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
    const depth = planned[bone] ? planned[bone].depth : null;
    for (let i = 0; i < b.n; ++i) {
      let rgb;
      if (mode === 'resection') {
        rgb = depth && depth[i] > 0.01 ? rampColour(-2 * depth[i] / planDepthMax) : untested;
      } else if (mode === 'levels') {
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
    if (mode === 'resection') {
      const stops = [0, 0.25, 0.5, 1].map((w) => `rgb(${rampColour(-2 * w)}) ${100 * w}%`);
      $('legend').style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      $('legend-labels').innerHTML = [0, planDepthMax / 4, planDepthMax / 2, planDepthMax]
          .map((x) => `<span>${x.toFixed(2)}</span>`).join('') + '<span>mm</span>';
      $('legend-note').innerHTML = 'depth of bone the plan removes (resection_mm); grey: none';
      return;
    }
    if (mode === 'levels') {
      const t = scene.levels_thresholds_mm;
      const stops = palette.pelvis.map((c, k) => `rgb(${c}) ${100 * k / palette.pelvis.length}% ${100 * (k + 1) / palette.pelvis.length}%`);
      $('legend').style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      const mm = (x) => Number(x.toFixed(2));
      $('legend-note').innerHTML = `none: <span class="swatch" style="background:rgb(${palette.femur[0]})"></span> femur, ` +
          `<span class="swatch" style="background:rgb(${palette.pelvis[0]})"></span> pelvis; ` +
          `<span class="swatch" style="background:rgb(${palette.untested})"></span> not tested (beyond reach, no surface)`;
      $('legend-labels').innerHTML = ['&gt;' + mm(t[0])].concat(t.slice(1).map((x, k) => `${mm(t[k])}-${mm(x)}`))
          .concat(['&le;' + mm(t[t.length - 1])]).map((s) => `<span>${s}</span>`).join('') + '<span>mm</span>';
    } else {
      const lo = RAMP[0][0], hi = RAMP[RAMP.length - 1][0];
      const stops = RAMP.map(([x, c]) => `rgb(${c}) ${100 * (x - lo) / (hi - lo)}%`);
      $('legend').style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      $('legend-labels').innerHTML = RAMP.map(([x]) => `<span>${x}</span>`).join('') + '<span>mm</span>';
      $('legend-note').innerHTML = `<span class="swatch" style="background:rgb(${palette.untested})"></span> ` +
          'not measured (beyond the distance reach, or no surface on the ray)';
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
      ['closest contact', s.contact_class ? s.contact_class.replaceAll('_', ' ') : 'none', ''],
      ['detection', fmt(f.ms, 1), 'ms'],
    ].map(([k, v, u]) => `<tr><td>${k}</td><td class="v">${v}</td><td>${u}</td></tr>`).join('');
  }

  let stopPlayback = () => {};  // set by a motion's timeline: a user's own pose pauses it
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
    if (stored) {  // an exported file shows the stored pose nearest the one asked for: the controls say which
      names.forEach((n, i) => { $(n).value = f.pose[i]; $(n + '-n').value = Number(f.pose[i].toFixed(2)); });
    }
    for (const w of hook.waiting.splice(0)) if (w.id <= f.id) w.resolve(f); else hook.waiting.push(w);
  }

  // The WebSocket: the newest pose only (the server drops older pending ones too).
  let nextId = 1;
  // Live: the server's WebSocket. Exported: the stored pose nearest the one asked for (said on the page).
  const storedFrames = stored ? stored.frames.map((f) => ({ pose: f.pose, buf: fromBase64(f.data) })) : null;
  const ws = stored ? { send: (text) => {
    const m = JSON.parse(text);
    let best = storedFrames[0], bestD = Infinity;
    for (const f of storedFrames) {
      const d = (f.pose[0] - m.pose[0]) ** 2 + (f.pose[1] - m.pose[1]) ** 2 + (f.pose[2] - m.pose[2]) ** 2;
      if (d < bestD) { bestD = d; best = f; }
    }
    setTimeout(() => applyFrame({ ...decodeFrame(best.buf, femur.n, pelvis.n), id: m.id }), 0);
  } } : new WebSocket(withToken(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`));
  ws.binaryType = 'arraybuffer';
  ws.onmessage = (e) => {
    if (typeof e.data === 'string') {
      const m = JSON.parse(e.data);
      if (m.type === 'error') {
        showError(m.message);
        for (const w of hook.waiting.splice(0)) {
          if (m.id !== undefined && w.id === m.id) w.reject(new Error(m.message)); else hook.waiting.push(w);
        }
      }
      return;
    }
    if (errorShownAt && performance.now() - errorShownAt > 4000) showError('');  // an error stays 4 s
    applyFrame(decodeFrame(e.data, femur.n, pelvis.n));
  };
  ws.onclose = () => {
    $('status').textContent = 'the server has stopped: restart impinge view and reload this page';
    for (const el of document.querySelectorAll('#panel input, #panel button, #panel select')) el.disabled = true;
    for (const w of hook.waiting.splice(0)) w.reject(new Error('the server has stopped'));
  };
  const opened = stored ? Promise.resolve() : new Promise((resolve) => { ws.onopen = resolve; });

  function sendPose(pose) {
    if (!stored && ws.readyState !== WebSocket.OPEN) return nextId;
    const id = nextId++;
    ws.send(JSON.stringify({ type: 'pose', id, pose }));
    return id;
  }
  const names = ['flexion', 'adduction', 'internal_rotation'];
  function currentPose() { return names.map((n) => Number($(n + '-n').value)); }
  for (const n of names) {
    $(n).addEventListener('input', () => { stopPlayback(); $(n + '-n').value = $(n).value; sendPose(currentPose()); });
    $(n + '-n').addEventListener('change', () => {
      const v = Number($(n + '-n').value);
      if ($(n + '-n').value.trim() === '' || !Number.isFinite(v) || Math.abs(v) > 360) {
        showError(`${n.replace('_', ' ')}: enter a number of degrees within -360..360`);
        $(n + '-n').value = last ? Number(last.pose[names.indexOf(n)].toFixed(2)) : 0;  // the pose shown
        return;
      }
      $(n).value = v;
      sendPose(currentPose());
    });
  }
  $('neutral').onclick = () => {
    stopPlayback();
    for (const n of names) { $(n).value = 0; $(n + '-n').value = 0; }
    sendPose([0, 0, 0]);
  };
  $('colour').onchange = recolour;
  if (!scene.distances) {  // --distances off: no Euclidean distances to colour by
    $('colour').querySelector('option[value=distance]').remove();
  }
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
    for (const [n, v] of [['flexion', f], ['adduction', a], ['internal_rotation', r]]) {
      $(n).value = v;
      $(n + '-n').value = Number(v.toFixed(2));
    }
    const id = sendPose([f, a, r]);
    return new Promise((resolve, reject) => hook.waiting.push({ id, resolve, reject }));
  };
  hook.colours = () => ({ femur: Array.from(femur.colour), pelvis: Array.from(pelvis.colour) });
  hook.setView = (name) => setView(name);  // anterior, lateral, medial, superior, oblique
  hook.positions = (bone) => Array.from((bone === 'femur' ? femur : pelvis).geometry.attributes.position.array);
  // For benchmarks/viewer_latency.py: the data path of `n` poses (a slider's change to the new values in the colour
  // buffer: request, detection, transfer, decode, colouring; not the draw), and the draw alone (one colour-buffer
  // upload and one render, waited for by reading a pixel back), each in ms.
  hook.timePoses = async (poses) => {
    const out = [];
    for (const p of poses) {
      const t0 = performance.now();
      await hook.setPose(...p);
      out.push(performance.now() - t0);
    }
    return out;
  };
  hook.timeDraws = (n) => {
    const gl = renderer.getContext(), out = [], px = new Uint8Array(4);
    for (let k = 0; k < n; ++k) {
      const t0 = performance.now();
      femur.geometry.attributes.color.needsUpdate = true;
      pelvis.geometry.attributes.color.needsUpdate = true;
      renderer.render(view, camera);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);  // waits for the drawing to finish
      out.push(performance.now() - t0);
    }
    hook.trianglesDrawn = renderer.info.render.triangles;  // what the last draw held (hidden or cropped parts not)
    return out;
  };
  hook.values = (bone, what) => Array.from(hook.frame[bone][what]);

  // A plan (--plan DIR): the resected bones, coloured by the depth removed, before and after; each target's limit.
  const planned = {};
  let colourBefore = 'levels';
  let planDepthMax = 0.1;
  if (scene.plan) {
    $('plan-panel').hidden = false;
    for (const bone of Object.keys(scene.plan.bones)) {
      const buf = await getBuffer(`/api/plan/mesh/${bone}`);
      const b = bone === 'femur' ? femur : pelvis;
      planned[bone] = { V: new Float32Array(buf, 0, b.n * 3), depth: new Float32Array(buf, b.n * 12, b.n),
                        before: Float32Array.from(b.geometry.attributes.position.array) };
      for (const d of planned[bone].depth) if (d > planDepthMax) planDepthMax = d;
    }
    const opt = document.createElement('option');
    opt.value = 'resection';
    opt.textContent = 'Resection depth (mm)';
    $('colour').append(opt);
    const f = (x, d = 1) => (x === null || x === undefined ? 'n/a' : Number(x).toFixed(d));
    $('plan').innerHTML = '<tr><td>target</td><td class="v">deg</td><td class="v">before</td><td class="v">after</td><td></td></tr>' +
      scene.plan.targets.map((t) => `<tr><td>${escapeHtml(String(t.target).replaceAll('_', ' '))}</td><td class="v">${f(t.target_deg)}</td>` +
        `<td class="v">${f(t.limit_before_deg)}</td><td class="v">${f(t.limit_after_deg)}</td><td>${t.met ? 'met' : 'missed'}</td></tr>`).join('') +
      Object.entries(scene.plan.bones).map(([b, x]) => `<tr><td colspan="5">${escapeHtml(b)}: ${f(x.volume_mm3, 0)} mm³, deepest ` +
        `${f(x.deepest_cut_mm, 2)} mm</td></tr>`).join('');
    $('plan-after').onchange = () => {
      const after = $('plan-after').checked;
      for (const [bone, p] of Object.entries(planned)) {
        const b = bone === 'femur' ? femur : pelvis;
        b.geometry.attributes.position.array.set(after ? p.V : p.before);
        b.geometry.attributes.position.needsUpdate = true;
        b.geometry.computeVertexNormals();
      }
      $('plan-note').textContent = after ? 'The bones after the resection, coloured by the depth removed; the ' +
          "sliders' gaps and distances are the bones' before it." : '';
      if (after) colourBefore = $('colour').value;
      $('colour').value = after ? 'resection' : (colourBefore === 'resection' ? 'levels' : colourBefore);
      recolour();
    };
    hook.planned = planned;
  }

  // The acetabular clock face (thesis Figure 62c; Blankenbaker et al. 2007): a ring over the rim with its hours.
  const clockGroup = new THREE.Group();
  if (scene.clock) {
    const c = new THREE.Vector3(...scene.clock.centre_mm), u12 = new THREE.Vector3(...scene.clock.twelve).normalize();
    const u3 = new THREE.Vector3(...scene.clock.three).normalize(), r = scene.clock.radius_mm + 3;
    const at = (h, rr) => c.clone().addScaledVector(u12, rr * Math.cos(h * Math.PI / 6))
        .addScaledVector(u3, rr * Math.sin(h * Math.PI / 6));
    const ring = [];
    for (let k = 0; k <= 120; ++k) ring.push(at(k / 10, r));
    clockGroup.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(ring),
                                  new THREE.LineBasicMaterial({ color: 0x333333 })));
    for (let h = 1; h <= 12; ++h) {
      clockGroup.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints([at(h, r - 2), at(h, r + 2)]),
                                    new THREE.LineBasicMaterial({ color: 0x333333 })));
      const cv = document.createElement('canvas');
      cv.width = cv.height = 64;
      const g = cv.getContext('2d');
      g.font = 'bold 40px sans-serif'; g.textAlign = 'center'; g.textBaseline = 'middle'; g.fillStyle = '#222';
      g.fillText(String(h), 32, 34);
      const label = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(cv), depthTest: false }));
      label.position.copy(at(h, r + 6));
      label.scale.set(6, 6, 1);
      clockGroup.add(label);
    }
    view.add(clockGroup);
  } else {
    $('show-clock').parentElement.hidden = true;
  }
  $('show-clock').onchange = () => { clockGroup.visible = $('show-clock').checked; requestDraw(); };

  // A motion (--motion): a timeline played in wall-clock time (frames skipped, never queued, when the answers are
  // slower than the motion), and the least distance over time (Joint.motion, computed once in the background).
  let motionGeneration = 0;
  async function setupMotion(file) {
    const query = file ? `?file=${encodeURIComponent(file)}` : '';
    const generation = ++motionGeneration;  // taken before the wait: the newest choice wins
    stopPlayback();
    const m = await getJSON('/api/motion' + query);
    if (generation !== motionGeneration) return;
    const n = m.time_s.length;
    $('motion-panel').hidden = false;
    $('motion-name').textContent = m.name;
    $('timeline').max = n - 1;
    let playing = false, startWall = 0, startT = 0, shown = -1;
    stopPlayback = () => { playing = false; $('play').textContent = 'Play'; };
    const showFrame = (k) => {
      k = Math.max(0, Math.min(n - 1, k));
      $('timeline').value = k;
      $('motion-time').textContent = `${m.time_s[k].toFixed(2)} s (frame ${k + 1} of ${n})`;
      if (k === shown) return;
      shown = k;
      const [f, a, r] = m.angles[k];
      for (const [id, v] of [['flexion', f], ['adduction', a], ['internal_rotation', r]]) {
        $(id).value = v; $(id + '-n').value = Number(v.toFixed(2));
      }
      sendPose([f, a, r]);
      drawPlot();
    };
    const frameAt = (t) => { let k = 0; while (k + 1 < n && m.time_s[k + 1] <= t) ++k; return k; };
    const tick = () => {
      if (!playing || generation !== motionGeneration) return;
      const t = startT + (performance.now() - startWall) / 1000 * Number($('speed').value);
      if (t > m.time_s[n - 1]) { playing = false; $('play').textContent = 'Play'; showFrame(n - 1); return; }
      showFrame(frameAt(t));
      requestAnimationFrame(tick);
    };
    $('play').onclick = () => {
      playing = !playing;
      $('play').textContent = playing ? 'Pause' : 'Play';
      if (playing) {
        if (shown >= n - 1) shown = -1, $('timeline').value = 0;
        startT = m.time_s[Number($('timeline').value)];
        startWall = performance.now();
        requestAnimationFrame(tick);
      }
    };
    $('speed').onchange = () => { startT = m.time_s[Math.max(0, shown)]; startWall = performance.now(); };
    $('timeline').oninput = () => { playing = false; $('play').textContent = 'Play'; showFrame(Number($('timeline').value)); };
    let least = null;
    const drawPlot = () => {
      const cv = $('plot'), g = cv.getContext('2d');
      g.clearRect(0, 0, cv.width, cv.height);
      if (!least) return;
      const y = least.least_distance_mm || least.least_gap_mm;
      const finite = y.filter((v) => v !== null);
      if (!finite.length) return;
      const lo = finite.reduce((a, v) => Math.min(a, v), 0), hi = finite.reduce((a, v) => Math.max(a, v), lo + 1);
      const X = (k) => 4 + (cv.width - 8) * k / Math.max(1, n - 1), Y = (v) => cv.height - 4 - (cv.height - 8) * (v - lo) / (hi - lo);
      g.strokeStyle = '#bbb'; g.beginPath(); g.moveTo(0, Y(0)); g.lineTo(cv.width, Y(0)); g.stroke();
      g.strokeStyle = '#1f5fbf'; g.beginPath();
      y.forEach((v, k) => { if (v !== null) (k ? g.lineTo(X(k), Y(v)) : g.moveTo(X(k), Y(v))); });
      g.stroke();
      if (shown >= 0) { g.strokeStyle = '#d22'; g.beginPath(); g.moveTo(X(shown), 0); g.lineTo(X(shown), cv.height); g.stroke(); }
      $('plot-note').textContent = `least ${least.least_distance_mm ? 'distance' : 'radial gap'} over the motion, ` +
          `${lo.toFixed(1)} to ${hi.toFixed(1)} mm (0: grey line)`;
    };
    hook.showFrame = showFrame;
    $('play').textContent = 'Play';
    poll('/api/motion/least' + query, (r) => { if (generation === motionGeneration) { least = r; hook.motionLeast = r; drawPlot(); } }, $('plot-note'));
  }
  if (scene.motion) await setupMotion(null);
  // --motion-folder: the page chooses among its motion files (the server reads only those).
  if (scene.motion_folder) {
    const list = await getJSON('/api/motions');
    $('motion-choice').hidden = false;
    $('motion-files').innerHTML = '<option value="">choose a motion file</option>' +
        list.files.map((f) => `<option value="${escapeHtml(f)}">${escapeHtml(f)}</option>`).join('');
    $('motion-files').onchange = () => { if ($('motion-files').value) setupMotion($('motion-files').value); };
    hook.chooseMotion = (f) => setupMotion(f);
  }

  // ROM limits (impinge rom's, computed once in the background) with the poses just before and at each limit.
  poll('/api/rom', (rows) => {
    $('rom-state').textContent = `limits in the ${rows.length ? rows[0].pelvic_frame : ''} frame; bony, beside the ` +
        'normal range of living subjects';
    $('rom').innerHTML = '<tr><td></td><td class="v">limit</td><td class="v">normal</td><td></td></tr>' + rows.map((r, k) =>
      `<tr><td>${r.motion.replaceAll('_', ' ')}</td><td class="v">${r.limit_deg === null ? 'free' : r.limit_deg.toFixed(1)}</td>` +
      `<td class="v">${r.normal_deg === null ? '' : r.normal_deg}</td><td>${r.pose_at_limit_deg ?
        `<button data-k="${k}" data-at="before">before</button><button data-k="${k}" data-at="at">at</button>` : ''}</td></tr>`).join('');
    for (const b of $('rom').querySelectorAll('button')) {
      b.onclick = () => {
        stopPlayback();
        const r = rows[Number(b.dataset.k)];
        const p = r.pose_at_limit_deg, q = p.slice();
        // Just before: 2 deg short of the limit along the motion (the standard motions are straight from their start).
        if (b.dataset.at === 'before' && r.limit_deg > 0) {
          const s = Math.max(0, r.limit_deg - 2) / r.limit_deg, start = r.start_deg;
          for (let i = 0; i < 3; ++i) q[i] = start[i] + (p[i] - start[i]) * s;
        }
        hook.setPose(...q);
      };
    }
    hook.rom = rows;
  }, $('rom-state'));

  // Morphology beside the view.
  poll('/api/morphology', (m) => {
    const f = (x, d = 1) => (x === null || x === undefined ? 'n/a' : x.toFixed(d));
    $('morph-state').textContent = '';
    const hours = Object.entries(m.alpha_deg_by_hour).sort((a, b) => Number(a[0]) - Number(b[0]))
        .map(([h, v]) => `${h}: ${f(v, 0)}`).join(', ');
    $('morph').innerHTML = [
      ['alpha angle, largest', `${f(m.alpha_max_deg)} deg at ${f(m.alpha_max_hour, 0)} o'clock`],
      ['alpha by hour', hours], ['head radius', `${f(m.head_radius_mm)} mm`],
      ['neck-shaft angle', `${f(m.neck_shaft_angle_deg)} deg`],
      ['femoral version (posterior condyles)', `${f(m.version_posterior_condylar_deg)} deg`],
      ['acetabular anteversion, inclination', `${f(m.radiographic_anteversion_deg)}, ${f(m.radiographic_inclination_deg)} deg`],
      ['centre-edge, lateral / anterior', `${f(m.lateral_centre_edge_deg)} / ${f(m.anterior_centre_edge_deg)} deg`],
    ].map(([k, v]) => `<tr><td>${k}</td><td>${v}</td></tr>`).join('');
    hook.morphology = m;
  }, $('morph-state'));

  display();
  setView('anterior');
  legend();
  await opened;
  await hook.setPose(0, 0, 0);
  hook.ready = true;
}

// Poll a background job (impinge.view's job states) until it is done; `el` shows its progress.
async function poll(path, done, el) {
  for (;;) {
    let r;
    try {
      r = await getJSON(path);
    } catch (e) {
      el.textContent = String(e);
      return;
    }
    if (r.state === 'done') { el.textContent = ''; done(r.result); return; }
    if (r.state === 'error') { el.textContent = r.message; return; }
    el.textContent = `computing... ${r.seconds} s`;
    await new Promise((res) => setTimeout(res, 500));
  }
}

window.__impinge = { ready: false, waiting: [], frame: null, draws: 0, drawMs: NaN, error: null };
start().catch((e) => { window.__impinge.error = String(e); showError(String(e)); });
