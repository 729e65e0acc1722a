// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors
//
// The live view's browser test, browser side (run by serve_browser.cc):
//
//   node drive.js CHROMIUM PORT SCREENSHOT.png
//
// Debian's headless Chromium loads the page palpate serve serves on PORT and
// is driven as a person would drive it: a mouse drag pushes the probe, the
// keys m (a material constant, through the page's prompt), d and a
// (detach, attach), shift-click (another active node), then a reload (a
// client that leaves and comes back). What the page shows is printed, one
// "KEY value..." line each, for the C++ side to check against the API; the
// page's own numbers come from window.palpate (the state the page draws).
// A screenshot is kept. Nothing here decides pass or fail except a timeout
// or a page error, which end the script with status 1.
"use strict";
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
           "--ignore-gpu-blocklist"]
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

  // The drag: down the screen, by 0.45 of the state space's extent,
  // over about a second (the device thread limits the HIP to 5 cm/s).
  const m = await page.evaluate(() => window.palpate.mesh);
  const pixels = Math.round(0.45 * m.extent / (m.diameter / 640));
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
  // camera's back axis, about +z here), not in the view plane.
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
  out("DEPTH", moved[2] > 0.8 * Math.hypot(...moved) && Math.hypot(...moved) > 0.2 * m.extent ? "yes" : "no",
      ...moved.map(x => x.toPrecision(6)));
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
  out("DEPTH_BUTTON", -away[2] > 0.8 * Math.hypot(...away) && Math.hypot(...away) > 0.2 * m.extent ? "yes" : "no",
      ...away.map(x => x.toPrecision(6)),
      await page.evaluate(() => document.getElementById("depth").textContent));

  // r: back to rest; then shift-click on the surface where a vertex far
  // from the active node shows (the ray through that pixel must hit the
  // surface there): another active node.
  await page.keyboard.press("r");
  await until(() => Math.hypot(...window.palpate.frame.hip) < 1e-9, 10000);
  const pick = await page.evaluate(() => {
    const s = window.palpate, v = s.mesh.vertices, a = s.frame.active;
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
        return { old: a, vertex: i, x: (q.x + 1) * window.innerWidth / 2, y: (1 - q.y) * window.innerHeight / 2 };
    }
    return { old: a, vertex: -1, x: window.innerWidth / 2, y: window.innerHeight / 2 };
  });
  await page.keyboard.down("Shift");
  await page.mouse.click(pick.x, pick.y);
  await page.keyboard.up("Shift");
  await until(a => window.palpate.frame.active !== a, 60000, pick.old);
  out("ACTIVE", pick.old, await page.evaluate(() => window.palpate.frame.active),
      await page.evaluate(() => document.getElementById("message").textContent));

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
  out("PAGE_ERRORS", errors.length, ...errors.map(e => JSON.stringify(e)));
  await browser.close();
  process.exit(errors.length ? 1 : 0);
})().catch(e => { console.error("drive.js:", e.message); process.exit(1); });
