#!/usr/bin/env bash
# The README's picture of Blender after a bake (docs/images/blender.png): Blender's window under Xvfb
# (apt-get install xvfb xauth), software OpenGL, scripts/blender_screenshot.py driving it.
#   scripts/make_blender_screenshot.sh [OUT.png] [SCENES_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$(realpath -m "${1:-$root/docs/images/blender.png}")"
scenes="$(realpath "${2:-$root/../shared/scenes}")"
xvfb-run -a -s "-screen 0 1600x960x24" blender --factory-startup --python "$root/scripts/blender_screenshot.py" -- "$out" "$scenes"
echo "$out"
