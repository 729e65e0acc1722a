// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors
//
// The README's screenshot of the live view (doc/images/serve.png), made
// again with
//
//   build/palpate serve parameters/liver-stvk.prm &
//   NODE_PATH=build/browser-test/node_modules node tests/browser/screenshot.js \
//     /usr/bin/chromium 8080 doc/images/serve.png
//
// The mouse pushes the liver into itself from the middle of the page (the
// first view faces the probe there) and holds it while the cloud follows;
// the picture is taken when the cloud around the probe is computed.
"use strict";
const puppeteer = require("puppeteer-core");
const [chromium, port, file] = process.argv.slice(2);
const sleep = ms => new Promise(r => setTimeout(r, ms));

(async () => {
  const browser = await puppeteer.launch({
    executablePath: chromium, headless: "new",
    args: ["--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]
  });
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 800 });
  await page.goto(`http://127.0.0.1:${port}/`);
  await page.waitForFunction(() => window.palpate && window.palpate.frame && window.palpate.frame.cloud_complete,
                             { timeout: 300000 });
  await page.mouse.move(600, 400);
  await page.mouse.down();
  for (let i = 1; i <= 30; ++i) { await page.mouse.move(600 - i, 400 + 2 * i); await sleep(40); }
  await page.mouse.up();
  await page.waitForFunction(() => {
    const f = window.palpate.frame;
    return Math.hypot(f.hip[0] - f.target[0], f.hip[1] - f.target[1], f.hip[2] - f.target[2]) < 1e-9;
  }, { timeout: 60000 });
  await sleep(1500);
  await page.screenshot({ path: file });
  await browser.close();
})().catch(e => { console.error("screenshot.js:", e.message); process.exit(1); });
