// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors
//
// The live view's browser test, browser side (run by serve_browser.cc):
//
//   node drive.js CHROMIUM PORT SCREENSHOT.png
//
// Debian's headless Chromium loads the page palpate serve serves on PORT and
// is driven as a person would drive it: the camera is turned (a left drag
// off the organ, a right drag on it), zoomed (the wheel) and panned (a
// middle drag), f centres it on the probe, a mouse drag on the organ pushes
// the probe, the keys m (a material constant, through the page's prompt),
// d and a (detach, attach), Alt and the depth button (the probe in
// depth), shift-click (another active node), v (the first view), then a
// reload (a client that leaves and comes back). Then a page of another site
// (served by a second HTTP server here, as http://evil.test:PORT2, a name
// the browser is told is this machine) tries to change the model and to
// read it, and the same name on the live view's port (DNS rebinding) tries
// again. What the page shows is printed, one
// "KEY value..." line each, for the C++ side to check against the API; the
// page's own numbers come from window.palpate (the state the page draws).
// A screenshot is kept. Nothing here decides pass or fail except a timeout
// or a page error, which end the script with status 1.
"use strict";
const http = require("http");
const puppeteer = require("puppeteer-core");

const [chromium, port, screenshot] = process.argv.slice(2);
const sleep = ms => new Promise(r => setTimeout(r, ms));
const out = (...words) => console.log(words.join(" "));
setTimeout(() => { console.error("drive.js: gave up after 300 s"); process.exit(1); }, 300000);

(async () => {
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: "new",
    args: ["--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader",
           "--ignore-gpu-blocklist",
           // Another site on this machine: evil.test is 127.0.0.1 to this
           // browser (as a rebinding attacker's name would be).
           "--host-resolver-rules=MAP evil.test 127.0.0.1"]
  });
  const page = await browser.newPage();
  await page.setViewport({ width: 960, height: 640 });
  const errors = [];
  page.on("pageerror", e => errors.push(e.message));
  page.on("console", m => { if (m.type() === "error") errors.push(m.text()); });
  let promptText = "";
  page.on("dialog", d => { promptText = d.message(); d.accept("Young's modulus=2e5"); });

  // Wait until fn() (run in the page) is true, at most ms.
  // If not, say what the page showed then.
  const until = (fn, ms, arg) => page.waitForFunction(fn, { timeout: ms, polling: 50 }, arg).catch(
    async e => {
      const f = await page.evaluate(() => {
        const f = window.palpate && window.palpate.frame;
        if (!f) return "no frame";
        const counts = [0, 0, 0, 0];
        for (let i = 3; i < f.cloud.length; i += 4) counts[f.cloud[i]] += 1;
        return JSON.stringify({ hip: f.hip, target: f.target, page_target: window.palpate.target,
                                force: f.force, attached: f.attached, missing: f.missing,
                                cloud_complete: f.cloud_complete, shape: f.shape, cloud: counts,
                                active: f.active, load: f.load,
                                message: document.getElementById("message").textContent });
      });
      throw new Error(`waiting for ${fn.toString()}: ${e.message}; the page showed ${f}`);
    });
  // The frame's cloud has no point left to compute (all computed or failed).
  const cloudDone = () => {
    const f = window.palpate.frame, c = f.cloud;
    for (let i = 3; i < c.length; i += 4) if (c[i] === 0 || c[i] === 3) return false;
    return f.cloud_complete && f.shape;
  };
  // The HIP is at the target the page sent (to 1e-9 m) and the cloud
  // around it computed.
  const settled = () => {
    const f = window.palpate.frame, t = window.palpate.target;
    return Math.hypot(f.hip[0] - f.target[0], f.hip[1] - f.target[1], f.hip[2] - f.target[2]) < 1e-12 &&
      Math.hypot(t[0] - f.target[0], t[1] - f.target[1], t[2] - f.target[2]) < 1e-9 && window.cloudDone();
  };

  await page.goto(`http://127.0.0.1:${port}/`);
  await page.evaluate(`window.cloudDone = ${cloudDone.toString()}`);
  await until(() => window.palpate && window.palpate.mesh && window.palpate.frame, 30000);
  await until(() => window.cloudDone(), 120000);
  const m = await page.evaluate(() => window.palpate.mesh);

  // The camera as the page holds it: its position, the point it turns
  // about, the probe's place on the screen (x, y from -1 to 1) and the
  // target the page sent for the probe.
  const view = () => page.evaluate(() => {
    const V = window.palpateView, c = V.controls(), q = V.probe().position.clone().project(V.camera);
    return { position: V.camera.position.toArray(), target: c.target.toArray(), probe: [q.x, q.y],
             probeTarget: window.palpate.target.slice() };
  });
  const sub = (a, b) => a.map((x, k) => x - b[k]);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const norm = a => Math.hypot(...a);
  // The angle (degrees) between the directions the camera looks from.
  const turned = (v, w) => {
    const a = sub(v.position, v.target), b = sub(w.position, w.target);
    return Math.acos(Math.min(1, dot(a, b) / (norm(a) * norm(b)))) * 180 / Math.PI;
  };
  const drag = async (from, by, button, steps) => {
    await page.mouse.move(from[0], from[1]);
    await page.mouse.down({ button: button });
    for (let i = 1; i <= steps; ++i) {
      await page.mouse.move(from[0] + Math.round(by[0] * i / steps), from[1] + Math.round(by[1] * i / steps));
      await sleep(20);
    }
    await page.mouse.up({ button: button });
  };

  // The first view: the angle between the direction it looks from and
  // the outward normal at the active node, the probe's distance from the
  // middle of the screen, and whether every surface vertex is in the
  // picture. The active node as /mesh, the frame and the page's text name
  // it.
  const first = await page.evaluate(() => {
    const V = window.palpateView, THREE = V.THREE, s = window.palpate, v = s.mesh.vertices;
    let inside = true;
    for (let i = 0; i < v.length; i += 3) {
      const q = new THREE.Vector3(v[i], v[i + 1], v[i + 2]).project(V.camera);
      inside = inside && Math.abs(q.x) < 1 && Math.abs(q.y) < 1;
    }
    return { inside: inside, active: [s.mesh.active, s.frame.active, document.getElementById("active").textContent] };
  });
  const v0 = await view();
  out("FIRST_VIEW", turned(v0, { position: m.normal, target: [0, 0, 0] }),
      norm(v0.probe), first.inside ? "yes" : "no");
  out("ACTIVE_NODE", ...first.active);

  // Turn: a left drag from a pixel where the canvas shows no organ or
  // probe, 120 pixels to the right; then a right drag that starts on the
  // probe, 60 pixels up. Neither moves the probe.
  const background = await page.evaluate(() => {
    const V = window.palpateView, THREE = V.THREE, canvas = document.querySelector("canvas");
    const ray = new THREE.Raycaster();
    for (let y = 120; y < 520; y += 20)
      for (let x = 900; x > 40; x -= 20) {
        if (document.elementFromPoint(x, y) !== canvas) continue;
        ray.setFromCamera(new THREE.Vector2(2 * x / window.innerWidth - 1, 1 - 2 * y / window.innerHeight), V.camera);
        if (ray.intersectObjects([V.organ(), V.probe()]).length === 0) return [x, y];
      }
    return null;
  });
  await drag(background, [120, 0], "left", 12);
  const v1 = await view();
  const onProbe = v1.probe.map((q, k) => k === 0 ? (q + 1) * 480 : (1 - q) * 320);
  await drag(onProbe, [0, -60], "right", 6);
  const v2 = await view();
  out("ORBIT", turned(v0, v1), turned(v1, v2), norm(sub(v2.probeTarget, v0.probeTarget)),
      background ? "from_background" : "no_background");
  // Zoom: the wheel, twice 200 up (toward the screen).
  await page.mouse.move(480, 320);
  await page.mouse.wheel({ deltaY: -200 });
  await sleep(50);
  await page.mouse.wheel({ deltaY: -200 });
  await sleep(50);
  const v3 = await view();
  out("ZOOM", norm(sub(v3.position, v3.target)) / norm(sub(v2.position, v2.target)), turned(v2, v3));
  // Pan: a middle drag of 80 pixels left and 40 down moves the point
  // the camera turns about by the same on the screen at its depth
  // (2 d tan(20 deg) / 640 metres per pixel at distance d); the
  // direction stays.
  await drag(background, [-80, 40], "middle", 8);
  const v4 = await view();
  const d3 = norm(sub(v3.position, v3.target));
  out("PAN", norm(sub(v4.target, v3.target)) / (Math.hypot(80, 40) * 2 * d3 * Math.tan(Math.PI / 9) / 640),
      turned(v3, v4));

  // f: the view centred on the probe, from the same direction and
  // distance: the probe's distance from the middle of the screen before
  // and after.
  await page.keyboard.press("f");
  const v5 = await view();
  out("LOOK_AT_PROBE", norm(v4.probe), norm(v5.probe), turned(v4, v5),
      norm(sub(v5.position, v5.target)) / norm(sub(v4.position, v4.target)));

  // The drag on the probe, in the view turned: down the screen, by 0.45
  // of the state space's extent (the page's metres per pixel at the
  // probe), over about a second (the device thread limits the HIP to
  // 5 cm/s). The target moves down the screen (the camera's -up) by
  // that much.
  const scale = await page.evaluate(() => window.palpateView.metresPerPixel());
  const pixels = Math.round(0.45 * m.extent / scale);
  const down = await page.evaluate(() => {
    const up = new window.palpateView.THREE.Vector3();
    window.palpateView.camera.matrixWorld.extractBasis(new window.palpateView.THREE.Vector3(), up,
                                                       new window.palpateView.THREE.Vector3());
    return up.negate().toArray();
  });
  const before = await page.evaluate(() => [window.palpate.received, performance.now()]);
  await page.mouse.move(480, 320);
  await page.mouse.down();
  const steps = 25;
  for (let i = 1; i <= steps; ++i) {
    await page.mouse.move(480, 320 + Math.round(pixels * i / steps));
    await sleep(40);
  }
  await page.mouse.up();
  await sleep(1000);
  const after = await page.evaluate(() => [window.palpate.received, performance.now()]);
  out("RATE", (after[0] - before[0]) / ((after[1] - before[1]) / 1000), "dragged_pixels", pixels);
  // The server's answer to /frame alone, without the page's drawing: the
  // median of 21 requests one after another. Nagle's algorithm with the
  // browser's delayed ACK made it 40-44 ms (serve.cc); the drawing's
  // share of the rate above depends on the machine's load.
  const trips = await page.evaluate(async () => {
    const t = [];
    for (let i = 0; i < 21; ++i) {
      const began = performance.now();
      await (await fetch("/frame")).text();
      t.push(performance.now() - began);
    }
    return t.sort((a, b) => a - b)[10];
  });
  out("FRAME_TRIP", trips);
  const dragged = sub(await page.evaluate(() => window.palpate.target.slice()), v5.probeTarget);
  out("DRAG", dot(dragged, down) / norm(dragged), norm(dragged) / (pixels * scale));
  await until(settled, 120000);
  // What the page shows: the force's text, and the frame's numbers.
  const shown = await page.evaluate(() => ({
    text: document.getElementById("force").textContent,
    frame: window.palpate.frame,
    target: window.palpate.target,
    engine: document.getElementById("engine").textContent
  }));
  const counts = [0, 0, 0, 0];
  for (let i = 3; i < shown.frame.cloud.length; i += 4) counts[shown.frame.cloud[i]] += 1;
  out("HIP", ...shown.frame.hip.map(x => x.toPrecision(17)));
  out("FORCE", ...shown.frame.force.map(x => x.toPrecision(17)));
  out("FORCE_TEXT", shown.text);
  out("TARGET", ...shown.frame.target.map(x => x.toPrecision(17)));
  out("CLOUD", counts.join(" "));
  out("ENGINE_TEXT", shown.engine);
  out("LOAD", shown.frame.load.workers, shown.frame.load.busy, shown.frame.load.queued);
  // The C++ side compares with the API now; the HIP stays where it is.
  // The screenshot: the probe pushing, the cloud around it.
  await sleep(500);
  await page.screenshot({ path: screenshot });

  // m: the paper's on-the-fly parameter change, through the page's prompt.
  await page.keyboard.press("m");
  await until(() => document.getElementById("message").textContent !== "", 10000);
  out("MATERIAL_TEXT", await page.evaluate(() => document.getElementById("message").textContent));
  out("PROMPT", promptText);
  const f0 = shown.frame.force;
  await until(f => {
    const g = window.palpate.frame.force;
    return window.cloudDone() && Math.hypot(g[0], g[1], g[2]) > 1.5 * Math.hypot(f[0], f[1], f[2]);
  }, 180000, f0);
  await sleep(200);
  out("FORCE_AFTER_MATERIAL", ...(await page.evaluate(() => window.palpate.frame.force)).map(x => x.toPrecision(17)));

  // d and a: detach, attach.
  await page.keyboard.press("d");
  await until(() => !window.palpate.frame.attached, 10000);
  await page.keyboard.press("a");
  await until(() => window.palpate.frame.attached, 10000);
  out("DETACH_ATTACH", "yes");

  // A drag down with Alt held moves the probe toward the viewer (the
  // camera's back axis), not in the view plane: the cosine of the angle
  // between the two.
  const back = await page.evaluate(() => {
    const T = window.palpateView.THREE, b = new T.Vector3();
    window.palpateView.camera.matrixWorld.extractBasis(new T.Vector3(), new T.Vector3(), b);
    return b.toArray();
  });
  const t0 = await page.evaluate(() => window.palpate.target.slice());
  await page.keyboard.down("Alt");
  await page.mouse.move(480, 320);
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) {
    await page.mouse.move(480, 320 + Math.round(pixels * i / 10));
    await sleep(20);
  }
  await page.mouse.up();
  await page.keyboard.up("Alt");
  const t1 = await page.evaluate(() => window.palpate.target.slice());
  const moved = t1.map((x, k) => x - t0[k]);
  out("DEPTH", dot(moved, back) / norm(moved), norm(moved) / m.extent);
  // The same with the page's depth button (touch screens, desktops that
  // take Alt-drag): a drag up, away from the viewer.
  await page.click("#depth");
  const t2 = await page.evaluate(() => window.palpate.target.slice());
  await page.mouse.move(480, 320);
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) {
    await page.mouse.move(480, 320 - Math.round(pixels * i / 10));
    await sleep(20);
  }
  await page.mouse.up();
  await page.click("#depth");
  const t3 = await page.evaluate(() => window.palpate.target.slice());
  const away = t3.map((x, k) => x - t2[k]);
  out("DEPTH_BUTTON", -dot(away, back) / norm(away), norm(away) / m.extent,
      await page.evaluate(() => document.getElementById("depth").textContent));

  // r: back to rest; then shift-click on the surface where a vertex far
  // from the active node shows (the ray through that pixel must hit the
  // surface there): another active node, the one of that vertex (its
  // number in the mesh file, from /mesh).
  await page.keyboard.press("r");
  await until(() => Math.hypot(...window.palpate.frame.hip) < 1e-9, 10000);
  const pick = await page.evaluate(() => {
    const s = window.palpate, v = s.mesh.vertices, a = s.mesh.nodes.indexOf(s.frame.active);
    const THREE = window.palpateView.THREE;
    const camera = window.palpateView.camera, organ = window.palpateView.organ();
    const at = i => new THREE.Vector3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    const order = [...Array(v.length / 3).keys()].sort((i, j) => at(j).distanceTo(at(a)) - at(i).distanceTo(at(a)));
    const ray = new THREE.Raycaster();
    for (const i of order) {
      const q = at(i).project(camera);
      if (Math.abs(q.x) > 0.9 || Math.abs(q.y) > 0.9) continue;
      ray.setFromCamera(new THREE.Vector2(q.x, q.y), camera);
      const hit = ray.intersectObject(organ)[0];
      if (hit && hit.point.distanceTo(at(i)) < 0.05 * s.mesh.diameter)
        return { old: s.frame.active, node: s.mesh.nodes[i], x: (q.x + 1) * window.innerWidth / 2,
                 y: (1 - q.y) * window.innerHeight / 2 };
    }
    return { old: s.frame.active, node: -1, x: window.innerWidth / 2, y: window.innerHeight / 2 };
  });
  await page.keyboard.down("Shift");
  await page.mouse.click(pick.x, pick.y);
  await page.keyboard.up("Shift");
  await until(a => window.palpate.frame.active !== a, 60000, pick.old);
  await until(() => document.getElementById("message").textContent.startsWith("active node: "), 10000);
  out("ACTIVE", pick.old, await page.evaluate(() => window.palpate.frame.active), pick.node,
      await page.evaluate(() => document.getElementById("active").textContent),
      await page.evaluate(() => document.getElementById("message").textContent));

  // v: the first view again.
  await page.keyboard.press("v");
  const v6 = await view();
  out("FIRST_VIEW_AGAIN", norm(sub(v6.position, v0.position)) / m.diameter,
      norm(sub(v6.target, v0.target)) / m.diameter);

  // A client that leaves and comes back: the page reloaded.
  await page.reload();
  await page.evaluate(`window.cloudDone = ${cloudDone.toString()}`);
  await until(() => window.palpate && window.palpate.frame && window.palpate.received > 10, 30000);
  out("RECONNECTED", "yes");

  // How much of the view is not background: the organ, the cloud and the
  // overlays must have been drawn.
  const drawn = await page.evaluate(() => {
    const c = document.querySelector("canvas"), g = document.createElement("canvas");
    g.width = c.width; g.height = c.height;
    const x = g.getContext("2d");
    x.drawImage(c, 0, 0);
    const d = x.getImageData(0, 0, g.width, g.height).data;
    // The background is the corner pixel's colour.
    let n = 0;
    for (let i = 0; i < d.length; i += 4)
      if (Math.abs(d[i] - d[0]) + Math.abs(d[i + 1] - d[1]) + Math.abs(d[i + 2] - d[2]) > 30) ++n;
    return n / (d.length / 4);
  });
  out("DRAWN", drawn);

  // A page of another site, in another tab: its scripts and its form try
  // to change the model (Young's modulus to 1e13, another active node,
  // detach), to read a frame, and to show the view in a frame of its own
  // (where a click would be a click on the view). Each outcome as the
  // page of the other site sees it: "blocked" (the browser did not send
  // it, or did not give the page the answer: CORS, and for no-cors
  // requests the live view's Cross-Origin-Resource-Policy), "opaque"
  // (sent, the answer hidden), or the status.
  const live = `http://127.0.0.1:${port}`;
  const other = http.createServer((req, res) => {
    res.writeHead(200, { "Content-Type": "text/html" });
    res.end(`<!doctype html><html><body>
<form id="form" method="POST" action="${live}/material" enctype="text/plain">
<input name="Young's modulus" value="1e13"></form>
<iframe id="framed" src="${live}/"></iframe>
</body></html>`);
  });
  await new Promise(r => other.listen(0, "127.0.0.1", r));
  const material = await page.evaluate(() => fetch("/material").then(r => r.json()));
  const evil = await browser.newPage();
  await evil.goto(`http://evil.test:${other.address().port}/`);
  await sleep(1000);  // the frame's answer
  const attempts = await evil.evaluate(async live => {
    const outcome = p => p.then(r => r.type === "opaque" ? "opaque" : "status_" + r.status, () => "blocked");
    const post = (path, init) => outcome(fetch(live + path, Object.assign({ method: "POST" }, init)));
    return [
      // As a script may send it without asking first (no preflight).
      await post("/material", { headers: { "Content-Type": "text/plain" }, body: "Young's modulus=1e13" }),
      await post("/active", { mode: "no-cors", headers: { "Content-Type": "text/plain" }, body: "node 1" }),
      // With the live view's headers (a guessed token): a preflight first.
      await post("/detach", { headers: { "Content-Type": "application/x-palpate",
                                          "X-Palpate-Token": "0".repeat(32) }, body: "" }),
      // A read.
      await outcome(fetch(live + "/frame"))
    ];
  }, live);
  const frame = evil.frames().find(f => f !== evil.mainFrame());
  const framed = frame ? await frame.evaluate(() => window.palpate ? "shown" : "not_shown").catch(() => "not_shown")
                       : "no_frame";
  out("OTHER_SITE", ...attempts, framed);
  // Its form, sent: the browser goes to the live view's answer.
  await Promise.all([evil.waitForNavigation({ timeout: 10000 }),
                     evil.evaluate(() => document.getElementById("form").submit())]);
  out("OTHER_SITE_FORM", await evil.evaluate(() => document.body.innerText.trim()));
  // DNS rebinding: the other site's name, now this machine, on the live
  // view's port; its page then asks its "own" server.
  const rebound = await evil.goto(`http://evil.test:${port}/`);
  const asked = await evil.evaluate(async () => {
    const status = p => p.then(r => "status_" + r.status, () => "blocked");
    return [
      await status(fetch("/frame")),
      await status(fetch("/material", { method: "POST", body: "Young's modulus=1e13",
                                        headers: { "Content-Type": "application/x-palpate",
                                                   "X-Palpate-Token": "0".repeat(32) } }))
    ];
  });
  out("REBINDING", "status_" + rebound.status(), ...asked);
  await evil.close();
  other.close();
  const materialAfter = await page.evaluate(() => fetch("/material").then(r => r.json()));
  out("YOUNGS_MODULUS", material.constants["Young's modulus"], materialAfter.constants["Young's modulus"]);
  out("PAGE_ERRORS", errors.length, ...errors.map(e => JSON.stringify(e)));
  await browser.close();
  process.exit(errors.length ? 1 : 0);
})().catch(e => { console.error("drive.js:", e.message); process.exit(1); });
