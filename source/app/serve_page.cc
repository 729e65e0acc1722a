// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The live view's page (palpate serve): HTML and JavaScript, drawn with
// three.js (from npm, compiled into palpate and served as /three.module.js
// and /three.core.js: live_view_assets.cc).

namespace palpate
{
  extern const char *const live_view_page;
  const char *const        live_view_page = R"page(<!doctype html>
<html>
<head>
<meta charset="utf-8">
<title>palpate live view</title>
<style>
  body { margin: 0; overflow: hidden; font: 13px sans-serif; background: #20242b; }
  #info { position: absolute; top: 8px; left: 8px; color: #eee;
          background: rgba(0,0,0,0.5); padding: 8px; border-radius: 4px; }
  #warn { color: #ffb347; }
  #message { color: #9fd0ff; }
  #events { color: #ffb347; font-size: 12px; }
  #plot { position: absolute; bottom: 8px; left: 8px; background: rgba(0,0,0,0.5); }
</style>
</head>
<body>
<div id="info">
  <b>palpate</b> <span id="scene"></span><br>
  force: <span id="force">-</span> N<br>
  HIP: <span id="hip">-</span> mm<br>
  states: <span id="states">-</span><br>
  engine: <span id="engine">-</span><br>
  view: <span id="rate">-</span><br>
  <span id="warn"></span><br>
  <span id="message"></span><br>
  <div id="events"></div>
  drag: move the probe &middot; depth: wheel, alt-drag or <button id="depth">drag in depth: off</button> (z)<br>
  a/d: attach/detach &middot; r: rest &middot; m: change a material constant &middot; shift-click: another active node
</div>
<canvas id="plot" width="320" height="100"></canvas>
<script type="module">
import * as THREE from "/three.module.js";
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
// Cloud point colours by status: not computed, computed, failure point,
// being computed, given in sRGB as the hex colours are. Vertex colours
// are linear: converted.
const cloudColors = [[0.55, 0.55, 0.55], [0.25, 0.9, 0.35], [1.0, 0.2, 0.2], [1.0, 0.85, 0.2]].map(c => {
  const linear = new THREE.Color().setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);
  return [linear.r, linear.g, linear.b];
});

// A request to the server: its answer as text, or (logged) why there is
// none; never an unhandled rejection.
function post(path, body) {
  return fetch(path, { method: "POST", body: body || "" }).then(r => r.text()).catch(e => {
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
  activeIndex = m.active;
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
  geometry.computeBoundingSphere();
  const c = geometry.boundingSphere.center, r = geometry.boundingSphere.radius;
  camera.position.set(c.x, c.y - 0.2 * r, c.z + 3.2 * r);
  camera.up.set(0, 1, 0);
  camera.lookAt(c);
  poll();
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
    if (f.active >= 0) activeIndex = f.active;
    const a = 3 * activeIndex;
    const x = new THREE.Vector3(rest[a] + f.hip[0], rest[a + 1] + f.hip[1], rest[a + 2] + f.hip[2]);
    const sp = m.sphere;
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

// The mouse as a 3-DOF device: drag in the view plane, wheel in depth.
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
function move(dx, dy, dz) {
  const m = state.mesh;
  if (!m) return;
  const scale = m.diameter / window.innerHeight;
  const right = new THREE.Vector3(), up = new THREE.Vector3(), back = new THREE.Vector3();
  camera.matrixWorld.extractBasis(right, up, back);
  const d = right.multiplyScalar(dx * scale).add(up.multiplyScalar(-dy * scale))
              .add(back.multiplyScalar(dz * scale));
  for (let k = 0; k < 3; ++k) {
    state.target[k] = Math.max(-m.extent, Math.min(m.extent, state.target[k] + d.getComponent(k)));
  }
  sendTarget();
}
// Pointer events: a mouse, a touchpad, a pen or a finger on a touch screen
// (touch-action none: the browser does not scroll or zoom the page).
renderer.domElement.style.touchAction = "none";
renderer.domElement.addEventListener("pointerdown", e => {
  dragging = true;
  last = [e.clientX, e.clientY];
  renderer.domElement.setPointerCapture(e.pointerId);
});
renderer.domElement.addEventListener("pointerup", () => { dragging = false; });
renderer.domElement.addEventListener("pointercancel", () => { dragging = false; });
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
renderer.domElement.addEventListener("wheel", e => { e.preventDefault(); move(0, 0, 0.2 * e.deltaY); },
                                     { passive: false });
// Shift-click on the surface: make the nearest surface node the active node.
renderer.domElement.addEventListener("click", e => {
  if (!e.shiftKey || !organ) return;
  const mouse = new THREE.Vector2(2 * e.clientX / window.innerWidth - 1,
                                  1 - 2 * e.clientY / window.innerHeight);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(mouse, camera);
  const hit = ray.intersectObject(organ)[0];
  if (!hit) return;
  const v = 3 * hit.face.a;  // a vertex of the face hit, at rest
  state.target = [0, 0, 0];
  post("/active", [rest[v], rest[v + 1], rest[v + 2]].map(x => x.toFixed(6)).join(","))
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
// The view, for a browser test that clicks on the surface (three.js is a
// module here, not a global).
window.palpateView = { THREE: THREE, camera: camera, organ: () => organ };
</script>
</body>
</html>
)page";
} // namespace palpate
