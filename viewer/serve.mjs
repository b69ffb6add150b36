// A static file server for the viewer (ES modules do not load from file:// URLs): viewer/ (with its
// node_modules) at /, and the folder of each file given on the command line at /data/. Used by
// screenshot.mjs; run alone it prints the URL that shows OUT.glb with the scene file's camera (without one, the
// camera the bake wrote into the glb):
//   node viewer/serve.mjs OUT.glb [SCENE.json]     (then open the printed URL)
import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import { extname, join, normalize, resolve, dirname, basename } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
                '.glb': 'model/gltf-binary', '.png': 'image/png' };

// Serves viewer/ at / and the given files (only those) at /data/NAME.
export function serve(files) {
  const data = new Map(files.map((f) => [basename(f), resolve(f)]));
  const server = createServer(async (req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    let file = null;
    if (path.startsWith('/data/')) file = data.get(path.slice(6)) ?? null;
    else {
      const p = normalize(join(here, path === '/' ? 'index.html' : path));
      if (p.startsWith(here)) file = p;   // nothing outside viewer/
    }
    try {
      if (!file) throw new Error('not served');
      const body = await readFile(file);
      res.writeHead(200, { 'Content-Type': types[extname(file)] ?? 'application/octet-stream' });
      res.end(body);
    } catch {
      res.writeHead(404);
      res.end();
    }
  });
  return new Promise((ok) => server.listen(0, '127.0.0.1', () => ok(server)));
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const [glb, scene] = process.argv.slice(2);
  if (!glb) { console.error('usage: node viewer/serve.mjs OUT.glb [SCENE.json]'); process.exit(2); }
  const server = await serve(scene ? [glb, scene] : [glb]);
  const { port } = server.address();
  console.log(`http://127.0.0.1:${port}/index.html?glb=/data/${encodeURIComponent(basename(glb))}` +
              (scene ? `&scene=/data/${encodeURIComponent(basename(scene))}` : ''));
}
