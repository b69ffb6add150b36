// Renders OUT.glb in viewer/index.html with headless Chromium (puppeteer-core driving Debian's chromium) and
// saves the canvas as a PNG of the scene camera's size (the scene file's camera, else the glb's).
// Usage: node viewer/screenshot.mjs OUT.glb [SCENE.json] SHOT.png [--exposure E] [--mode diffuse|standard]
//        [--shadowmask off] [--chromium PATH]   exit 0, 1 when the page fails (its error printed), 2 on bad arguments.
// Without --exposure the page takes the exposure the bake wrote into the glb (microshadow's frame's own).
// --drag DX,DY drags the mouse by (DX, DY) pixels from the canvas centre (an orbit) and --key K presses a key
// (M: the other mode) before the screenshot, as a user would.
import puppeteer from 'puppeteer-core';
import { basename } from 'node:path';
import { serve } from './serve.mjs';

const args = process.argv.slice(2);
const opt = { mode: 'diffuse', chromium: '/usr/bin/chromium' };
const pos = [];
for (let i = 0; i < args.length; i++) {
  if (args[i].startsWith('--')) opt[args[i].slice(2)] = args[++i];
  else pos.push(args[i]);
}
if (pos.length !== 2 && pos.length !== 3) { console.error('usage: node screenshot.mjs OUT.glb [SCENE.json] SHOT.png [--exposure E] [--mode M] [--shadowmask off]'); process.exit(2); }
const [glb, sceneFile, out] = pos.length === 3 ? pos : [pos[0], null, pos[1]];
const server = await serve(sceneFile ? [glb, sceneFile] : [glb]);
const { port } = server.address();
const browser = await puppeteer.launch({
  executablePath: opt.chromium, headless: true,
  // software WebGL (SwiftShader) in a container without a GPU
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
let rc = 0;
try {
  const page = await browser.newPage();
  // the page's errors, and its warnings (what the standard mode's live lights depart in)
  page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warn') console.error('page:', m.text()); });
  const { readFile } = await import('node:fs/promises');
  // the camera: the scene file's, else the one in the glb's scene extras (its JSON chunk, after the 12-byte
  // header and the chunk's 8)
  let scene;
  if (sceneFile) scene = JSON.parse(await readFile(sceneFile, 'utf8'));
  else {
    const b = await readFile(glb);
    const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
    scene = { camera: json.scenes?.[json.scene ?? 0]?.extras?.microshadow?.camera ?? {} };
  }
  await page.setViewport({ width: scene.camera.width ?? 1024, height: scene.camera.height ?? 768, deviceScaleFactor: 1 });
  const url = `http://127.0.0.1:${port}/index.html?glb=/data/${encodeURIComponent(basename(glb))}` +
              (sceneFile ? `&scene=/data/${encodeURIComponent(basename(sceneFile))}` : '') +
              `&mode=${encodeURIComponent(opt.mode)}` +
              (opt.exposure !== undefined ? `&exposure=${encodeURIComponent(opt.exposure)}` : '') +
              (opt.shadowmask !== undefined ? `&shadowmask=${encodeURIComponent(opt.shadowmask)}` : '');
  await page.goto(url);
  await page.waitForFunction('window.viewerReady || window.viewerError', { timeout: 60000 });
  const error = await page.evaluate('window.viewerError');
  if (error) { console.error(`viewer: ${error}`); rc = 1; }
  else {
    if (opt.drag) {
      const [dx, dy] = opt.drag.split(',').map(Number);
      const cx = (scene.camera.width ?? 1024) / 2, cy = (scene.camera.height ?? 768) / 2;
      await page.mouse.move(cx, cy);
      await page.mouse.down();
      for (let k = 1; k <= 8; k++) await page.mouse.move(cx + dx * k / 8, cy + dy * k / 8);
      await page.mouse.up();
    }
    if (opt.key) await page.keyboard.press(opt.key);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
    await page.evaluate(() => document.querySelectorAll('.ui').forEach((e) => e.remove()));   // the canvas alone
    const canvas = await page.$('canvas');
    await canvas.screenshot({ path: out });
    console.log(`${out}: ${scene.camera.width}x${scene.camera.height} screenshot of ${glb}`);
  }
} finally {
  await browser.close();
  server.close();
}
process.exit(rc);
