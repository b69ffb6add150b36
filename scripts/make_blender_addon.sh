#!/usr/bin/env bash
# Packs the Blender add-on as a zip Blender installs (Edit > Preferences > Add-ons > Install...): the add-on
# (blender/microshadow_blender) with the Python module (python/microshadow) and a built libmicroshadow.so in
# its lib/ folder, where the add-on looks first (blender/microshadow_blender/library.py). The library links
# the system's shared libraries (Embree, libpng, ...): the zip is for machines with the same packages.
#   scripts/make_blender_addon.sh BUILD_DIR OUT.zip
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 BUILD_DIR OUT.zip" >&2; exit 2; }
root="$(cd "$(dirname "$0")/.." && pwd)"
lib="$1/libmicroshadow.so"
[ -f "$lib" ] || { echo "$0: $lib not found (build the library first)" >&2; exit 2; }
out="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cp -r "$root/blender/microshadow_blender" "$work/"
mkdir -p "$work/microshadow_blender/lib"
cp -r "$root/python/microshadow" "$work/microshadow_blender/lib/"
cp -L "$lib" "$work/microshadow_blender/lib/libmicroshadow.so"
find "$work" -name __pycache__ -prune -exec rm -rf {} +
rm -f "$out"
(cd "$work" && python3 -m zipfile -c "$out" microshadow_blender)
echo "$out"
