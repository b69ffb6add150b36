#!/usr/bin/env bash
# Regenerates every picture under docs/images from where it was made, so that they stay current:
#   builtin.png          the README's first command (the CLI's built-in scene, its default anti-aliasing)
#   sibenik-*.png        docs/cameras.md: docs/examples/sibenik-*.json (shared scenes), 256x256, latlong 512x256
#   foliage.png          docs/shading.md: scripts/make_foliage_scene.py, scanline, 1024 samples
#   sun*.png             docs/lights.md ("The sun"): scripts/make_sun_scene.py, 1024 samples
#   real_spot.png        docs/real-assets.md: Spot from the assets folder (spot/spot/spot.json), 480x480
#   real_igea.png        docs/real-assets.md: Igea from the assets folder (igea_scene.json), 480x480
#   asset-emitter-public-cornell.png   docs/lights.md: Vinc3r's Cornell box glTF (assets folder
#                        cornellbox/BJS-2.80-Eevee-gltf), lit by its own emitter, no light in the scene file
#   bake_*.png, frame_builtin.png   docs/baking.md: scripts/make_bake_images.sh (the bake pictures' own script)
# Pictures whose inputs are absent (the shared scenes, the real assets: never committed) are skipped with a
# message and left as they are. No docs picture comes from the dense scenes (scripts/make_dense_scenes.py).
# Usage: scripts/make_docs_images.sh [BINARY] [ASSETS_DIR]
#   defaults: ./build/microshadow and ../assets beside the repository; the shared scenes are read where the
#   examples name them, ../shared/scenes beside the repository.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$repo/build/microshadow}")
assets=${2:-$repo/../assets}
out=$repo/docs/images
[ -x "$bin" ] || { echo "make_docs_images: $bin is not an executable (build it: cmake --build build --target microshadow_cli)" >&2; exit 2; }
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
made=0 skipped=0
render() {   # render NAME ARGS...: one picture, into a staging file first (a failed run leaves the old one)
    local name=$1; shift
    echo "make_docs_images: $name" >&2
    "$bin" "$@" --quiet -o "$tmp/$name"
    mv "$tmp/$name" "$out/$name"
    made=$((made + 1))
}
skip() { echo "make_docs_images: skipping $1: $2" >&2; skipped=$((skipped + 1)); }

render builtin.png

if [ -f "$repo/../shared/scenes/sibenik/sibenik.obj" ]; then
    for cam in pinhole orthographic fisheye parabolic; do
        render "sibenik-$cam.png" "$repo/docs/examples/sibenik-$cam.json" --width 256 --height 256
    done
    render sibenik-latlong.png "$repo/docs/examples/sibenik-latlong.json" --width 512 --height 256
else
    skip "sibenik-*.png" "the shared scenes are not at $repo/../shared/scenes"
fi

if command -v python3 > /dev/null; then
    python3 "$repo/scripts/make_foliage_scene.py" "$tmp/foliage" > /dev/null
    render foliage.png "$tmp/foliage/foliage.json" --method scanline --samples 1024
else
    skip foliage.png "python3 is needed for scripts/make_foliage_scene.py"
fi

if command -v python3 > /dev/null; then
    python3 "$repo/scripts/make_sun_scene.py" "$tmp/sun"
    render sun.png "$tmp/sun/sun.json" --exposure -1
    render sun_base.png "$tmp/sun/sun_base.json" --exposure -1
    render sun_tip.png "$tmp/sun/sun_tip.json" --exposure -1
else
    skip "sun*.png" "python3 is needed for scripts/make_sun_scene.py"
fi

if [ -f "$assets/spot/spot/spot.json" ]; then
    render real_spot.png "$assets/spot/spot/spot.json" --width 480 --height 480
else
    skip real_spot.png "$assets/spot/spot/spot.json is absent (docs/real-assets.md: where Spot comes from)"
fi
if [ -f "$assets/igea_scene.json" ] && [ -f "$assets/igea.ply" ]; then
    render real_igea.png "$assets/igea_scene.json" --width 480 --height 480
else
    skip real_igea.png "$assets/igea_scene.json or igea.ply is absent (docs/real-assets.md: where Igea comes from)"
fi

cornell=$assets/cornellbox/BJS-2.80-Eevee-gltf/assets/cornellBox-2.80-Eevee-gltf.gltf
if [ -f "$cornell" ]; then
    # no "light" and no "lights": the glTF's emissive lamp becomes the scene's lights (docs/lights.md)
    cat > "$tmp/cornell.json" <<JSON
{"meshes": [{"file": "$cornell"}], "allow_outside_paths": true,
 "camera": {"eye": [0, 1.5, 4.5], "target": [0, 1.5, 0], "up": [0, 1, 0], "fov_y": 62, "width": 800, "height": 450}}
JSON
    render asset-emitter-public-cornell.png "$tmp/cornell.json" --method scanline
else
    skip asset-emitter-public-cornell.png "$cornell is absent (docs/lights.md: where the Cornell box comes from)"
fi

# >>> bake pictures hook (docs/baking.md): made by their own script when it exists <<<
if [ -x "$repo/scripts/make_bake_images.sh" ]; then
    "$repo/scripts/make_bake_images.sh" "$bin"
else
    skip "bake_builtin.png, bake_quad.png, frame_builtin.png" "scripts/make_bake_images.sh does not exist yet"
fi

echo "make_docs_images: $made pictures made, $skipped skipped, in $out" >&2
