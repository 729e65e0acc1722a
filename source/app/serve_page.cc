// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The live view's page (palpate serve): HTML and JavaScript, drawn with
// three.js (from npm, compiled into palpate and served as /three.module.js
// and /three.core.js, with its OrbitControls as /OrbitControls.js:
// live_view_assets.cc).

namespace palpate
{
  extern const char *const live_view_page;
  const char *const        live_view_page = R"page(<!doctype html>
<html>
<head>
<meta charset="utf-8">
<!-- The run's secret, written in by the server: the page sends it back
     with every change (below, post()). -->
<meta name="palpate-token" content="{{palpate-token}}">
<title>palpate live view</title>
<style>
  body { margin: 0; overflow: hidden; font: 13px sans-serif; background: #20242b; }
  #info { position: absolute; top: 8px; left: 8px; color: #eee;
          background: rgba(0,0,0,0.5); padding: 8px; border-radius: 4px; }
  #warn { color: #ffb347; }
  #message { color: #9fd0ff; }
  #events { color: #ffb347; font-size: 12px; }
  #plot { position: absolute; bottom: 8px; left: 8px; background: rgba(0,0,0,0.5); }
  #help { position: absolute; bottom: 8px; right: 8px; color: #ccc; font-size: 12px;
          background: rgba(0,0,0,0.5); padding: 6px 8px; border-radius: 4px; line-height: 1.5; }
</style>
</head>
<body>
<div id="info">
  <b>palpate</b> <span id="scene"></span><br>
  force: <span id="force">-</span> N<br>
  HIP: <span id="hip">-</span> mm &middot; active node <span id="active">-</span><br>
  states: <span id="states">-</span><br>
  engine: <span id="engine">-</span><br>
  view: <span id="rate">-</span><br>
  <span id="warn"></span><br>
  <span id="message"></span><br>
  <div id="events"></div>
</div>
<div id="help">
  probe: drag on the organ &middot; in depth: alt-drag or <button id="depth">drag in depth: off</button> (z)<br>
  view: drag elsewhere or right-drag turns &middot; middle- or shift-right-drag pans &middot; wheel zooms<br>
  f: look at the probe &middot; v: first view &middot; a/d: attach/detach &middot; r: rest<br>
  m: change a material constant &middot; shift-click: another active node
</div>
<canvas id="plot" width="320" height="100"></canvas>
<!-- OrbitControls imports "three": the same module as the page's. -->
<script type="importmap">{ "imports": { "three": "/three.module.js" } }</script>
<script type="module">
import * as THREE from "/three.module.js";
import { OrbitControls } from "/OrbitControls.js";
// Errors show on the page (and to a browser test reading it).
function showError(message) {
  document.getElementById("warn").textContent = "page error: " + message;
}
window.addEventListener("error", e => showError(e.message));
window.addEventListener("unhandledrejection", e => showError(String(e.reason)));
// window.palpate: what the page knows (for a browser test too): the mesh,
// the last frame, the frames received and when.
const state = { mesh: null, frame: null, forces: [], target: [0, 0, 0], received: 0,
                times: [], events: [] };
// Antialiasing, unless the WebGL is a software renderer (no GPU: a VM,
// headless Chromium), where it cost the page a third of its frame rate.
function softwareRenderer() {
  const gl = document.createElement("canvas").getContext("webgl");
  const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}
const renderer = new THREE.WebGLRenderer({ antialias: !softwareRenderer(), preserveDrawingBuffer: true });
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0x20242b);
document.body.insertBefore(renderer.domElement, document.body.firstChild);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.001, 100);
// Intensities times pi: three.js's lights are physical since r155.
scene.add(new THREE.AmbientLight(0x606060, Math.PI));
const light = new THREE.DirectionalLight(0xffffff, 0.8 * Math.PI);
light.position.set(1, 2, 3);
scene.add(light);
let organ = null, probe = null, arrow = null, rest = null, activeIndex = -1, cloudPoints = null;
// The camera's orbit, pan and zoom (made when the surface has come: the
// first view depends on it); surfaceOf: a node's number in the mesh file
// (the one the scene report and Active node / Node id use, and the only
// one the page shows or sends) -> its index among the surface's vertices.
let controls = null, surfaceOf = new Map();
// Cloud point colours by status: not computed, computed, failure point,
// being computed, given in sRGB as the hex colours are. Vertex colours
// are linear: converted.
const cloudColors = [[0.55, 0.55, 0.55], [0.25, 0.9, 0.35], [1.0, 0.2, 0.2], [1.0, 0.85, 0.2]].map(c => {
  const linear = new THREE.Color().setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);
  return [linear.r, linear.g, linear.b];
});

// A change sent to the server: its answer as text, or (logged) why there
// is none; never an unhandled rejection. Every change carries the run's
// token (which only this page holds: a page of another site cannot read
// it) in a header of its own, with the live view's own content type: the
// server refuses anything else (a page served by an earlier run, whose
// token is stale, is told to reload).
const token = document.querySelector('meta[name="palpate-token"]').content;
function post(path, body) {
  return fetch(path, { method: "POST", body: body || "",
                       headers: { "Content-Type": "application/x-palpate", "X-Palpate-Token": token } })
    .then(r => r.text().then(text => {
      if (r.status === 403) logEvent(path + ": " + text);
      return text;
    })).catch(e => {
      const text = path + ": the server does not answer (" + e.message + ")";
      logEvent(text);
      return text;
    });
}

// The surface, then the frames; a server not up yet is asked again.
function loadMesh() {
  fetch("/mesh").then(r => {
    if (!r.ok) throw new Error("the server answers " + r.status);
    return r.json();
  }).then(start, e => {
    logEvent("the surface did not come (" + e.message + "); retrying");
    setTimeout(loadMesh, 1000);
  });
}
function start(m) {
  state.mesh = m;
  document.getElementById("scene").textContent = m.scene + " (" + m.engine + ")";
  rest = new Float32Array(m.vertices);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(m.vertices), 3));
  geometry.setIndex(m.triangles);
  geometry.computeVertexNormals();
  organ = new THREE.Mesh(geometry, new THREE.MeshPhongMaterial(
    { color: 0xb0505a, side: THREE.DoubleSide, flatShading: false }));
  scene.add(organ);
  // Fixed nodes: small blue points.
  const fixed = new THREE.BufferGeometry();
  const fx = [];
  for (const i of m.fixed) fx.push(m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]);
  fixed.setAttribute("position", new THREE.BufferAttribute(new Float32Array(fx), 3));
  scene.add(new THREE.Points(fixed, new THREE.PointsMaterial({ color: 0x4080ff, size: m.diameter / 60 })));
  m.nodes.forEach((id, i) => surfaceOf.set(id, i));
  activeIndex = surfaceOf.has(m.active) ? surfaceOf.get(m.active) : -1;
  document.getElementById("active").textContent = m.active;
  // The probe: a marker at the active node, or the indenter itself (a
  // half-transparent sphere of its radius, so the dent shows through).
  probe = m.sphere ?
    new THREE.Mesh(new THREE.SphereGeometry(m.sphere[3], 32, 24),
                   new THREE.MeshPhongMaterial({ color: 0xffd040, transparent: true, opacity: 0.55 })) :
    new THREE.Mesh(new THREE.SphereGeometry(m.diameter / 80, 16, 12),
                   new THREE.MeshPhongMaterial({ color: 0xffd040 }));
  scene.add(probe);
  // The state cloud (the paper's Fig. 1): grey not computed yet, yellow
  // being computed, green computed, red failure points; it follows the
  // probe.
  cloudPoints = new THREE.Points(new THREE.BufferGeometry(),
    new THREE.PointsMaterial({ size: m.diameter / 150, vertexColors: true }));
  cloudPoints.frustumCulled = false;  // its points change every frame
  scene.add(cloudPoints);
  arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.01, 0x40ff80);
  // Drawn over the organ: the force often points into it, behind its
  // surface as the camera sees it.
  for (const part of [arrow.line, arrow.cone]) {
    part.material.depthTest = false;
    part.renderOrder = 1;
  }
  scene.add(arrow);
  firstView(m, geometry);
  poll();
}

// The first view faces the probe: it looks against the outward normal of
// the surface at the active node (the server's), at the point of the
// normal's line level with the organ's centre, so that the probe is in the
// middle of the view whatever the mesh's coordinates (an organ in CT
// coordinates touched from below would otherwise hide it), from as near as
// shows every surface vertex with a sixth of the view to spare (the
// panels cover the corners).
function firstView(m, geometry) {
  geometry.computeBoundingSphere();
  const c = geometry.boundingSphere.center, r = geometry.boundingSphere.radius;
  const n = new THREE.Vector3(m.normal[0], m.normal[1], m.normal[2]);
  if (n.length() < 0.5) n.set(0, 0, 1);  // no active node: from +z
  n.normalize();
  const a = activeIndex >= 0 ? new THREE.Vector3(rest[3 * activeIndex], rest[3 * activeIndex + 1],
                                                 rest[3 * activeIndex + 2]) : c.clone();
  const centre = a.clone().addScaledVector(n, c.clone().sub(a).dot(n));
  // Up: y, or z if the normal is near y, so that the orbit's
  // axis (the camera's up) is never the view's direction.
  camera.up.set(0, Math.abs(n.y) < 0.9 ? 1 : 0, Math.abs(n.y) < 0.9 ? 0 : 1);
  camera.position.copy(centre).addScaledVector(n, r);
  camera.lookAt(centre);
  camera.updateMatrixWorld();
  // A vertex at height y and width x across the view and h along n from
  // the centre is in the view from a distance d when |y| <= (d - h)
  // tan(fov / 2) and |x| <= (d - h) tan(fov / 2) aspect.
  const right = new THREE.Vector3(), up = new THREE.Vector3(), back = new THREE.Vector3();
  camera.matrixWorld.extractBasis(right, up, back);
  const tanY = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)), tanX = tanY * camera.aspect;
  let distance = 0;
  for (let i = 0; i < rest.length; i += 3) {
    const p = new THREE.Vector3(rest[i], rest[i + 1], rest[i + 2]).sub(centre);
    distance = Math.max(distance, p.dot(n) + 1.2 * Math.max(Math.abs(p.dot(right)) / tanX,
                                                            Math.abs(p.dot(up)) / tanY));
  }
  camera.position.copy(centre).addScaledVector(n, distance);
  camera.lookAt(centre);
  // The controls take the camera's up when made: made now. The left button
  // turns the view unless the probe's drag takes the press (below); the
  // right turns it anywhere (with Shift, Ctrl or Meta: pans, as three.js
  // makes any turning button do); the middle pans; the wheel zooms.
  controls = new OrbitControls(camera, renderer.domElement);
  controls.mouseButtons = { LEFT: THREE.MOUSE.ROTATE, MIDDLE: THREE.MOUSE.PAN, RIGHT: THREE.MOUSE.ROTATE };
  controls.target.copy(centre);
  controls.minDistance = 0.01 * r;
  controls.maxDistance = 20 * distance;
  controls.update();
  controls.saveState();  // v: back to this view
  controls.addEventListener("change", requestDraw);
  requestDraw();
}

// f: the view centred on the probe, from the same direction and distance
// (the orbit then turns about the probe).
function lookAtProbe() {
  if (!controls || !probe) return;
  const shift = probe.position.clone().sub(controls.target);
  controls.target.add(shift);
  camera.position.add(shift);
  controls.update();
}

// A log of what happened (missing data, failure points, the server gone),
// newest first, with the time since the page loaded.
// The same event again within 3 s adds to its line ("x 4") instead of
// pushing the others out.
function logEvent(text, count) {
  const now = performance.now() / 1000, e = state.events[0];
  if (e && e.text === text && now - e.last < 3) {
    e.last = now;
    e.count += count || 1;
  } else {
    state.events.unshift({ text: text, first: now, last: now, count: count || 1 });
    state.events.length = Math.min(state.events.length, 5);
  }
  document.getElementById("events").innerHTML = state.events.map(e =>
    e.first.toFixed(1) + (e.last > e.first ? "-" + e.last.toFixed(1) : "") + " s: " + e.text +
    (e.count > 1 ? " (x " + e.count + ")" : "")).join("<br>");
}

// Frames at about 30 Hz: the next request 33 ms after the last one began,
// never two at once; a server that stops answering is retried every 0.5 s.
function poll() {
  const began = performance.now();
  fetch("/frame").then(r => {
    if (!r.ok) throw new Error("it answers " + r.status);
    return r.text();
  }).then(text => {
    if (state.lost) { logEvent("the server answers again"); state.lost = false; }
    // A frame like the last (nothing moved, nothing computed) is counted
    // but not drawn again: a software renderer's time goes to the solvers.
    if (text === state.lastText) {
      state.received += 1;
      state.times.push(performance.now());
      if (state.times.length > 60) state.times.shift();
    } else {
      try {
        show(JSON.parse(text));
        state.lastText = text;
      } catch (e) {
        logEvent("a frame could not be shown: " + e.message);
      }
    }
    setTimeout(poll, Math.max(0, 33 - (performance.now() - began)));
  }, e => {
    if (!state.lost) logEvent("the server does not answer (" + e.message + "); retrying");
    state.lost = true;
    setTimeout(poll, 500);
  });
}

function show(f) {
    const previous = state.frame;
    state.frame = f;
    state.received += 1;
    state.times.push(performance.now());
    if (state.times.length > 60) state.times.shift();
    if (previous && f.missing !== previous.missing && f.missing !== "none")
      logEvent("missing data: " + f.missing + (f.missing === "not computed yet" ?
               " (the force fades to zero)" : " (the force is held)"));
    if (previous && f.failed > previous.failed)
      logEvent("new failure points (no equilibrium found there)", f.failed - previous.failed);
    const m = state.mesh, p = organ.geometry.attributes.position;
    for (let i = 0; i < p.array.length; ++i) p.array[i] = rest[i] + f.displacement[i];
    p.needsUpdate = true;
    organ.geometry.computeVertexNormals();
    if (surfaceOf.has(f.active)) activeIndex = surfaceOf.get(f.active);
    document.getElementById("active").textContent = f.active;
    const a = 3 * activeIndex;
    const x = new THREE.Vector3(rest[a] + f.hip[0], rest[a + 1] + f.hip[1], rest[a + 2] + f.hip[2]);
    const sp = f.sphere;  // where the sphere is now: another active node moves it
    probe.position.copy(sp ? new THREE.Vector3(sp[0] + f.hip[0], sp[1] + f.hip[1], sp[2] + f.hip[2]) : x);
    const c = f.cloud, n = c.length / 4, xyz = new Float32Array(3 * n), rgb = new Float32Array(3 * n);
    for (let i = 0; i < n; ++i) {
      for (let k = 0; k < 3; ++k) {
        xyz[3 * i + k] = rest[a + k] + m.spacing * c[4 * i + k];
        rgb[3 * i + k] = cloudColors[c[4 * i + 3]][k];
      }
    }
    cloudPoints.geometry.setAttribute("position", new THREE.BufferAttribute(xyz, 3));
    cloudPoints.geometry.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
    const force = new THREE.Vector3(f.force[0], f.force[1], f.force[2]);
    const magnitude = force.length();
    if (magnitude > 1e-9) {
      arrow.visible = true;
      arrow.position.copy(x);
      arrow.setDirection(force.clone().normalize());
      arrow.setLength(0.02 * m.diameter * magnitude + 0.005);
    } else {
      arrow.visible = false;
    }
    document.getElementById("force").textContent =
      f.force.map(v => v.toFixed(3)).join(", ") + " (|f| = " + magnitude.toFixed(3) + ")";
    document.getElementById("hip").textContent = f.hip.map(v => (1000 * v).toFixed(1)).join(", ");
    document.getElementById("states").textContent = f.available + " computed, " + f.failed +
      " failure points" + (f.cloud_complete ? "" : " (initial cloud in progress)");
    document.getElementById("warn").textContent =
      (f.attached ? "" : "detached ") + (f.missing !== "none" ? "missing data: " + f.missing : "");
    const l = f.load;
    document.getElementById("engine").textContent = l.busy + " of " + l.workers + " workers solving, " +
      l.queued + " queued, " + l.states_per_second.toFixed(1) + " states/s, " +
      (100 * l.utilisation).toFixed(0) + " % busy";
    const t = state.times;
    if (t.length > 1)
      document.getElementById("rate").textContent =
        ((t.length - 1) * 1000 / (t[t.length - 1] - t[0])).toFixed(0) + " frames/s";
    state.forces.push(magnitude);
    if (state.forces.length > 320) state.forces.shift();
    plot();
    requestDraw();
}

function plot() {
  const canvas = document.getElementById("plot"), g = canvas.getContext("2d");
  g.clearRect(0, 0, canvas.width, canvas.height);
  const top = Math.max(1, ...state.forces);
  g.strokeStyle = "#40ff80";
  g.beginPath();
  state.forces.forEach((v, i) => {
    const y = canvas.height - 4 - (canvas.height - 8) * v / top;
    if (i === 0) g.moveTo(i, y); else g.lineTo(i, y);
  });
  g.stroke();
  g.fillStyle = "#eee";
  g.fillText("|f| (N), max " + top.toFixed(2), 4, 12);
}

// The mouse as a 3-DOF device: a drag on the organ moves the probe in the
// view plane, one with Alt (or the depth button) in depth.
// Targets go one at a time (so they arrive in order), at most every 16 ms;
// what moved meanwhile goes next, so the last target always arrives.
let dragging = false, last = null, sending = false, again = false;
function sendTarget() {
  if (sending) { again = true; return; }
  sending = true;
  const began = performance.now();
  post("/hip", state.target.map(v => v.toFixed(9)).join(",")).then(() => {
    setTimeout(() => {
      sending = false;
      if (again) { again = false; sendTarget(); }
    }, Math.max(0, 16 - (performance.now() - began)));
  });
}
// Metres per pixel at the probe's depth in the view: the probe follows the
// mouse whatever the zoom.
function metresPerPixel() {
  const ahead = camera.getWorldDirection(new THREE.Vector3());
  const depth = Math.max(camera.near, probe.position.clone().sub(camera.position).dot(ahead));
  return 2 * depth * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) / window.innerHeight;
}
function move(dx, dy, dz) {
  const m = state.mesh;
  if (!m || !probe) return;
  const scale = metresPerPixel();
  const right = new THREE.Vector3(), up = new THREE.Vector3(), back = new THREE.Vector3();
  camera.matrixWorld.extractBasis(right, up, back);
  const d = right.multiplyScalar(dx * scale).add(up.multiplyScalar(-dy * scale))
              .add(back.multiplyScalar(dz * scale));
  for (let k = 0; k < 3; ++k) {
    state.target[k] = Math.max(-m.extent, Math.min(m.extent, state.target[k] + d.getComponent(k)));
  }
  sendTarget();
}
// The organ (or the probe) under the pointer, if any.
function organAt(e) {
  const ray = new THREE.Raycaster();
  ray.setFromCamera(new THREE.Vector2(2 * e.clientX / window.innerWidth - 1,
                                      1 - 2 * e.clientY / window.innerHeight), camera);
  return ray.intersectObjects([organ, probe])[0];
}
// Pointer events: a mouse, a touchpad, a pen or a finger on a touch screen
// (touch-action none: the browser does not scroll or zoom the page).
// Whether a press moves the probe or the view is decided here, before the
// controls see it (a capturing listener runs first): the left button on
// the organ or the probe, anywhere with Alt or the depth button on, moves
// the probe, and the controls sit this press out; a shift-click on the
// organ picks a node and moves nothing. Any other press is the view's.
let holding = false;  // the controls are off for this press
renderer.domElement.style.touchAction = "none";
renderer.domElement.addEventListener("pointerdown", e => {
  if (!organ || e.button !== 0) return;
  const onOrgan = organAt(e) !== undefined;
  if (e.shiftKey ? !onOrgan : !(onOrgan || e.altKey || depthDrag)) return;
  holding = true;
  controls.enabled = false;
  // Its release comes here, wherever the pointer is then.
  renderer.domElement.setPointerCapture(e.pointerId);
  if (e.shiftKey) return;
  dragging = true;
  last = [e.clientX, e.clientY];
}, { capture: true });
function release() {
  dragging = false;
  if (holding) { holding = false; controls.enabled = true; }
}
renderer.domElement.addEventListener("pointerup", release);
renderer.domElement.addEventListener("pointercancel", release);
// With Alt held (a touchpad without a wheel), a drag up moves the probe
// away from the viewer, down toward. Desktops that take Alt-drag to move
// windows, and touch screens, have the button (or z): while it is on,
// every drag moves in depth.
let depthDrag = false;
function toggleDepth() {
  depthDrag = !depthDrag;
  document.getElementById("depth").textContent = "drag in depth: " + (depthDrag ? "on" : "off");
}
document.getElementById("depth").addEventListener("click", toggleDepth);
renderer.domElement.addEventListener("pointermove", e => {
  if (!dragging) return;
  if (e.altKey || depthDrag) move(0, 0, e.clientY - last[1]);
  else move(e.clientX - last[0], e.clientY - last[1], 0);
  last = [e.clientX, e.clientY];
});
// Shift-click on the surface: the node of the triangle hit nearest to
// the point hit becomes the active node, sent by its number in the mesh
// file.
renderer.domElement.addEventListener("click", e => {
  if (!e.shiftKey || !organ) return;
  const ray = new THREE.Raycaster();
  ray.setFromCamera(new THREE.Vector2(2 * e.clientX / window.innerWidth - 1,
                                      1 - 2 * e.clientY / window.innerHeight), camera);
  const hit = ray.intersectObject(organ)[0];
  if (!hit) return;
  const p = organ.geometry.attributes.position;
  const at = i => new THREE.Vector3(p.getX(i), p.getY(i), p.getZ(i));
  const corners = [hit.face.a, hit.face.b, hit.face.c];
  const nearest = corners.reduce((i, j) => at(j).distanceTo(hit.point) < at(i).distanceTo(hit.point) ? j : i);
  state.target = [0, 0, 0];
  post("/active", "node " + state.mesh.nodes[nearest])
    .then(t => { document.getElementById("message").textContent = "active node: " + t; });
});
window.addEventListener("keydown", e => {
  if (e.key === "m") {
    // The paper's on-the-fly parameter change: a constant of the material.
    // The model's constants as they are now, as the example.
    fetch("/material").then(r => r.json()).then(mat => {
      const now = Object.entries(mat.constants).map(([k, v]) => k + "=" + v);
      const change = window.prompt("A constant of " + mat.model + " as ENTRY=VALUE (now: " +
                                   now.join(", ") + ")", now.length ? now[0] : "");
      if (change) post("/material", change)
        .then(t => { document.getElementById("message").textContent = t; });
    }).catch(e => logEvent("the material's constants did not come (" + e.message + ")"));
  }
  if (e.key === "a") post("/attach");
  if (e.key === "d") post("/detach");
  // Rest: the target goes after any sent before it.
  if (e.key === "r") { state.target = [0, 0, 0]; sendTarget(); }
  if (e.key === "z") toggleDepth();
  if (e.key === "f") lookAtProbe();
  if (e.key === "v" && controls) controls.reset();
});
window.addEventListener("resize", () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
  requestDraw();
});
// Drawn when something changed (a frame came, the window was resized), not
// at every animation frame: a software renderer (a machine without a GPU,
// headless Chromium) would spend the page's time drawing the same picture.
let redraw = true;
function requestDraw() { redraw = true; }
(function animate() {
  requestAnimationFrame(animate);
  if (redraw) { redraw = false; renderer.render(scene, camera); }
})();
window.palpate = state;
loadMesh();
// The view, for a browser test that clicks on the surface and turns the
// camera (three.js is a module here, not a global).
window.palpateView = { THREE: THREE, camera: camera, organ: () => organ, probe: () => probe,
                       controls: () => controls, metresPerPixel: metresPerPixel };
</script>
</body>
</html>
)page";
} // namespace palpate
