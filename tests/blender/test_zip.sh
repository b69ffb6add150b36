#!/usr/bin/env bash
# The add-on as a user installs it: the zip of scripts/make_blender_addon.sh installed into a fresh user scripts
# folder by Blender's own operator, enabled, and F12 with microshadow on Blender's default scene (its cube and
# point light), the Python module and the library taken from the zip (no MICROSHADOW_LIBRARY, no PYTHONPATH).
#   tests/blender/test_zip.sh BLENDER BUILD_DIR WORK_DIR
set -euo pipefail
blender=$1 build=$2 work=$3
root="$(cd "$(dirname "$0")/../.." && pwd)"
rm -rf "$work"
mkdir -p "$work/scripts"
"$root/scripts/make_blender_addon.sh" "$build" "$work/microshadow_addon.zip" >/dev/null
unset MICROSHADOW_LIBRARY PYTHONPATH
export BLENDER_USER_SCRIPTS="$work/scripts"
cat > "$work/check.py" <<PY
import os
import bpy
bpy.ops.preferences.addon_install(filepath="$work/microshadow_addon.zip")
bpy.ops.preferences.addon_enable(module="microshadow_blender")
sc = bpy.context.scene
sc.render.engine = "MICROSHADOW"
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 64, 48, 100
sc.render.image_settings.file_format = "OPEN_EXR"
sc.render.filepath = "$work/f12.exr"
bpy.ops.render.render(write_still=True)
import microshadow
where = os.path.realpath(microshadow.__file__)
assert where.startswith(os.path.realpath("$work/scripts")), "the module came from " + where
assert os.environ["MICROSHADOW_LIBRARY"].startswith("$work/scripts"), os.environ["MICROSHADOW_LIBRARY"]
img = bpy.data.images.load("$work/f12.exr")
px = img.pixels[:]
lit = sum(1 for i in range(0, len(px), 4) if px[i] > 1e-3)
print("zip install: module %s, %d of %d pixels lit" % (where, lit, len(px) // 4))
assert lit > len(px) // 4 // 20, "too few pixels lit"  # an exception: --python-exit-code makes it Blender's exit code
PY
"$blender" -b --factory-startup --python-exit-code 1 --python "$work/check.py"
