// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors
//
// benchmarks/run serve, browser side:
//   node serve-page.js CHROMIUM PORT SECONDS WIDTH HEIGHT
// Headless Chromium opens the live view and keeps it open for SECONDS; every
// frame the page receives is counted as "solving" (some worker was solving)
// or "idle". Prints one line: PAGE solving_frames solving_s idle_frames idle_s
"use strict";
const puppeteer = require("puppeteer-core");
const [chromium, port, seconds, width, height] = process.argv.slice(2);

(async () => {
  const browser = await puppeteer.launch({
    executablePath: chromium, headless: "new",
    args: ["--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]
  });
  const page = await browser.newPage();
  await page.setViewport({ width: Number(width), height: Number(height) });
  await page.goto(`http://127.0.0.1:${port}/`);
  await page.waitForFunction(() => window.palpate && window.palpate.frame, { timeout: 60000 });
  const r = await page.evaluate(async ms => {
    // Between two frames, the time counts for the phase of the first.
    const s = window.palpate, t = { solving: [0, 0], idle: [0, 0] };
    let n = s.received, last = performance.now(), phase = s.frame.load.busy > 0 ? "solving" : "idle";
    const end = last + ms;
    while (performance.now() < end) {
      await new Promise(r => setTimeout(r, 5));
      if (s.received === n) continue;
      const now = performance.now();
      t[phase][0] += s.received - n;
      t[phase][1] += (now - last) / 1000;
      n = s.received; last = now;
      phase = s.frame.load.busy > 0 ? "solving" : "idle";
    }
    return t;
  }, 1000 * Number(seconds));
  console.log("PAGE", r.solving[0], r.solving[1], r.idle[0], r.idle[1]);
  await browser.close();
})().catch(e => { console.error("serve-page.js:", e.message); process.exit(1); });
