#!/usr/bin/env bash
# The images of docs/baking.md, into docs/images/: the Quad's and the built-in scene's lightmaps, a frame of the
# built-in scene, and the Stanford bunny (../shared/scenes) baked into a glTF, shown by the three.js viewer in
# headless chromium beside microshadow's own frame of the same camera. Prints the bunny bake's summary line
# (bake time, texels/s, seams) and the validator's verdict on its glb. With HELMET_DIR set to a folder holding
# Khronos' FlightHelmet sample (FlightHelmet.gltf; fetched by hand, it is not in ../shared), the same three
# pictures of it on a ground with two rect lights, baked with the default options; with MIXED_DIR set to
# Bevy's assets/models/MixedLightingExample folder (MixedLightingExample.gltf), the same of it; with SPONZA=1,
# the same of Crytek's Sponza converted to glTF from ../shared (scripts/sponza_gltf.py; needs assimp-utils).
# Usage: [HELMET_DIR=DIR] [MIXED_DIR=DIR] [SPONZA=1] scripts/make_bake_images.sh [BUILD_DIR]   (a Release build: default build/; needs node, chromium and
# viewer/node_modules for the viewer's image: scripts/install-deps.sh)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
ms=$build/microshadow
out=$root/docs/images
scenes=$(cd "$root/.." && pwd)/shared/scenes
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"

# The Quad (its OBJ has no UV set 1: xatlas) and the built-in scene with a frame of it.
"$ms" bake "$scenes/quad/quad.json" --uv 1 --size 256 --samples 1024 -o "$tmp/quad.exr" --png "$out/bake_quad.png" --quiet
"$ms" bake --uv xatlas --size 512 --samples 1024 -o "$tmp/builtin.exr" --png "$out/bake_builtin.png" --quiet
"$ms" --width 512 --height 384 --samples 1024 -o "$out/frame_builtin.png"

# The bunny: its lightmap, the glb, the viewer's screenshot at the scene file's camera (512 x 512 here), the frame.
# The shared scene file as it is, but for the ground's texel density: a quarter (its "lightmap" scale), so that
# the bunny, not the 4 m of ground around it, gets most of the atlas.
shared=$scenes/stanford-bunny/stanford-bunny.json
bunny=$tmp/stanford-bunny.json
/usr/bin/python3 -c "
import json, os; s = json.load(open('$shared')); d = os.path.dirname('$shared')
s['meshes'] = [{'file': os.path.join(d, m['file']), **({'lightmap': {'scale': 0.25}} if m['file'] == 'ground.obj' else {})}
               for m in s['meshes']]
json.dump(s, open('$bunny', 'w'), indent=1)"
"$ms" bake "$bunny" --uv xatlas --size 1024 --samples 1024 -o "$tmp/bunny.exr" --png "$out/bake_bunny_lightmap.png" \
    --gltf "$tmp/bunny.glb" 2>&1 | grep -v '^bake: ' | tee "$tmp/bake.log"
node "$root/viewer/validate.mjs" "$tmp/bunny.glb"
"$ms" "$bunny" --width 512 --height 512 --samples 1024 -o "$out/bake_bunny_frame.png"
# the viewer needs the frame's exposure (the 99th percentile of unshadowed radiance to 1) and the camera at 512 x 512
exposure=$(MICROSHADOW_LIBRARY="$build/libmicroshadow.so" PYTHONPATH="$root/python" /usr/bin/python3 -c "
import microshadow as ms
print(ms.render(ms.load('$bunny'), width=512, height=512, samples=1024)['exposure'])")
/usr/bin/python3 -c "
import json; s = json.load(open('$bunny')); s['camera']['width'] = s['camera']['height'] = 512
json.dump({'camera': s['camera']}, open('$tmp/camera.json', 'w'))"
node "$root/viewer/screenshot.mjs" "$tmp/bunny.glb" "$tmp/camera.json" "$out/bake_bunny_viewer.png" --exposure "$exposure"

# An asset's three pictures from its scene file $tmp/NAME.json: the default bake at 1024² (its lightmap, and its glb
# through the validator), the viewer's screenshot with the exposure the bake wrote, the --shading diffuse frame.
asset_pictures() {
  "$ms" bake "$tmp/$1.json" --size 1024 -o "$tmp/$1.exr" --png "$out/bake_$1_lightmap.png" --gltf "$tmp/$1.glb" \
      2>&1 | grep -v '^bake: '
  node "$root/viewer/validate.mjs" "$tmp/$1.glb"
  node "$root/viewer/screenshot.mjs" "$tmp/$1.glb" "$tmp/$1.json" "$out/bake_$1_viewer.png"
  "$ms" "$tmp/$1.json" --shading diffuse -o "$out/bake_$1_frame.png"
}

# The FlightHelmet on a 2 x 2 ground, two rect lights (20 W above, 10 W from the side), default bake options at
# 1024²; the viewer takes the exposure the bake wrote into the glb, the frame is --shading diffuse (what a
# lightmap can show).
if [ -n "${HELMET_DIR:-}" ]; then
  printf 'v -1 -0.4404 -1\nv 1 -0.4404 -1\nv 1 -0.4404 1\nv -1 -0.4404 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nf 1/1/1 3/3/1 2/2/1\nf 1/1/1 4/4/1 3/3/1\n' >"$tmp/ground.obj"
  cat >"$tmp/helmet.json" <<EOF
{ "meshes": [ { "file": "$(cd "$HELMET_DIR" && pwd)/FlightHelmet.gltf" }, { "file": "ground.obj" } ],
  "camera": { "eye": [0.6, 0.2, 0.9], "target": [0, -0.15, 0], "up": [0, 1, 0], "fov_y": 45, "width": 512, "height": 512 },
  "lights": [ { "corner": [-0.3, 0.8, 0.1], "edge_s": [0.4, 0, 0], "edge_t": [0, 0, 0.4], "power": 20 },
              { "corner": [0.8, -0.3, -0.2], "edge_s": [0, 0, 0.4], "edge_t": [0, 0.4, 0], "power": 10 } ] }
EOF
  asset_pictures helmet
fi

# Bevy's MixedLightingExample (a ground, a sphere and the four parts of the SheenChair, each with a TEXCOORD_1 of
# its own), two rect lights (40 W above the chair, 15 W from the side; its punctual sun left out), default bake
# options at 1024².
if [ -n "${MIXED_DIR:-}" ]; then
  cat >"$tmp/mixed.json" <<EOF
{ "meshes": [ { "file": "$(cd "$MIXED_DIR" && pwd)/MixedLightingExample.gltf" } ],
  "camera": { "eye": [1.4, 1.0, 1.5], "target": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 45, "width": 512, "height": 512 },
  "lights": [ { "corner": [0.2, 1.6, 0.0], "edge_s": [0.5, 0, 0], "edge_t": [0, 0, 0.5], "power": 40 },
              { "corner": [-1.2, 0.4, -0.6], "edge_s": [0, 0, 0.5], "edge_t": [0, 0.5, 0], "power": 15 } ] }
EOF
  asset_pictures mixed
fi

# Crytek's Sponza as glTF (scripts/sponza_gltf.py: the shared scene's OBJ parts in one glb, plain grey
# materials), with the shared scene's camera and light, default bake options at 1024².
if [ "${SPONZA:-0}" = 1 ]; then
  /usr/bin/python3 "$root/scripts/sponza_gltf.py" "$scenes/crytek-sponza-partial" "$tmp/Sponza.glb"
  /usr/bin/python3 -c "
import json; s = json.load(open('$scenes/crytek-sponza-partial/crytek-sponza-partial.json'))
s['meshes'] = [{'file': 'Sponza.glb'}]; s['camera']['width'] = s['camera']['height'] = 512
json.dump(s, open('$tmp/sponza.json', 'w'), indent=1)"
  asset_pictures sponza
fi
