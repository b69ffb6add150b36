#!/usr/bin/env bash
# The CLI's MPI mode (built with -DMS_MPI=ON; docs/mpi.md), against the single-process CLI as the oracle:
#   - frames: 2 and 3 ranks (oversubscribed), every schedule, give V, S and the PNG byte for byte equal to one
#     process, on the built-in scene (grid scanline, interleaved raytrace with its frame-wide filter, hpc with
#     its frame-level entry) and on a shared scene (skipped with a message when ../shared/scenes is absent);
#   - three lights (rect, disk, sphere) and materials with a specular lobe: the EXR with every light's channels
#     and the shaded PNG byte for byte equal to one process (scanline, interleaved raytrace, hpc); with a
#     textured light too; ranks given that scene with and without the texture, or with another material
#     colour, refuse to run (exit 2);
#   - bakes: 2 and 3 ranks give the single-process lightmap (EXR: R, G, B, S, V; with several lights every
#     light's S and V) and preview byte for byte, also of the three-light and the textured scene; ranks given
#     other lights refuse to bake;
#   - the stats report every rank, and the ranks' tiles add up to the frame's;
#   - hpc-scanline, whose answer at a pixel depends on the whole frame, is refused on 2 ranks (exit 2);
#   - a rank given an unreadable scene ends the run with exit code 2, that rank's one message line, and no
#     output file.
# usage: test_mpi.sh MICROSHADOW MPIEXEC SHARED_SCENES TMPDIR
set -uo pipefail
ms=${1:?} mpiexec=${2:?} scenes=${3:?} tmp=${4:?}
rm -rf "$tmp" && mkdir -p "$tmp" && cd "$tmp" || exit 1
# Root (CI) needs OpenMPI's consent; --quiet drops mpirun's own banners so that stderr is microshadow's.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export ASAN_OPTIONS=${ASAN_OPTIONS:-}:detect_leaks=0   # OpenMPI's own allocations, if sanitized
run() { "$mpiexec" --quiet --oversubscribe "$@"; }
fail=0
check() { if "$@"; then :; else echo "FAIL: $*"; fail=1; fi; }

# frame NAME SCENE_ARGS... : one process, then 2 and 3 ranks under each schedule, compared byte for byte.
frame() {
    local name=$1; shift
    "$ms" "$@" --threads 1 --quiet -o "$name-1.png" --vis "$name-1-v.pfm" --shadow "$name-1-s.pfm" || { echo "FAIL: $name: single process"; fail=1; return; }
    for r in 2 3; do
        for sched in queue counter static; do
            local o="$name-$r-$sched"
            run -n $r "$ms" "$@" --threads 1 --quiet --mpi-schedule $sched -o "$o.png" --vis "$o-v.pfm" --shadow "$o-s.pfm" \
                --stats "$o.json"
            check test $? -eq 0
            check cmp -s "$name-1-v.pfm" "$o-v.pfm"
            check cmp -s "$name-1-s.pfm" "$o-s.pfm"
            check cmp -s "$name-1.png" "$o.png"
            check python3 - "$o.json" "$r" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1])); m = s["mpi"]; r = int(sys.argv[2])
tiles = ((s["width"] + 15) // 16) * ((s["height"] + 15) // 16)
assert m["ranks"] == r and len(m["per_rank"]) == r, m
assert sum(p["units"] for p in m["per_rank"]) == tiles, (m, tiles)
EOF
        done
    done
    echo "ok: frame $name: 2 and 3 ranks, queue/counter/static = one process"
}
frame builtin --width 96 --height 72 --samples 256
frame interleaved --width 96 --height 72 --samples 256 --method raytrace --pattern interleaved
frame hpc --width 80 --height 48 --samples 256 --method hpc
if [ -f "$scenes/dabrovic-sponza/dabrovic-sponza.json" ]; then
    frame sponza "$scenes/dabrovic-sponza/dabrovic-sponza.json" --width 64 --height 48 --samples 256
else
    echo "skipped: $scenes/dabrovic-sponza absent (the shared scenes): no shared-scene frame"
fi

# Several lights (rect, disk, sphere) and OBJ/MTL materials, one specular: the EXR (R, G, B and every light's
# V and S channels) and the PNG, whose shading sums the lights with S_spec, byte for byte against one process.
printf 'newmtl matte\nKd 0.8 0.3 0.1\n\nnewmtl shiny\nKd 0.9 0.9 0.9\nPm 0.5\nPr 0.3\n' > m.mtl
printf '%s\n' 'mtllib m.mtl' 'v -3 0 -3' 'v 0 0 -3' 'v 3 0 -3' 'v -3 0 3' 'v 0 0 3' 'v 3 0 3' \
    'v -0.7 1 -0.7' 'v 0.7 1 -0.7' 'v 0.7 1 0.7' 'v -0.7 1 0.7' \
    'usemtl matte' 'f 4 5 2' 'f 4 2 1' 'usemtl shiny' 'f 5 6 3' 'f 5 3 2' 'f 7 9 8' 'f 7 10 9' > m.obj
printf '%s\n' '{ "meshes": [ { "file": "m.obj" } ],' \
    '  "camera": { "eye": [0, 4, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 55, "width": 70, "height": 50 },' \
    '  "lights": [ { "corner": [-1, 3, -1], "edge_s": [2, 0, 0], "edge_t": [0, 0, 2], "emission": [3, 3, 3] },' \
    '    { "shape": "disk", "center": [1.5, 2.5, 0], "normal": [-1, -2, 0], "radius": 0.6, "emission": [4, 2, 1] },' \
    '    { "shape": "sphere", "center": [-1.5, 2, 1], "radius": 0.4, "emission": [1, 2, 4] } ],' \
    '  "render": { "samples": 256 } }' > lights.json
lights() {
    local name=$1; shift
    "$ms" lights.json "$@" --threads 1 --quiet -o "$name-1.exr" || { echo "FAIL: $name: single process"; fail=1; return; }
    "$ms" lights.json "$@" --threads 1 --quiet -o "$name-1.png" || { echo "FAIL: $name: single process"; fail=1; return; }
    for r in 2 3; do
        local sched=counter
        [ $r = 3 ] && sched=static
        run -n $r "$ms" lights.json "$@" --threads 1 --quiet --mpi-schedule $sched -o "$name-$r.exr"
        check test $? -eq 0
        check cmp -s "$name-1.exr" "$name-$r.exr"
        run -n $r "$ms" lights.json "$@" --threads 1 --quiet --mpi-schedule queue --mpi-chunk 2 -o "$name-$r.png"
        check test $? -eq 0
        check cmp -s "$name-1.png" "$name-$r.png"
    done
    echo "ok: frame $name: three lights and materials, 2 and 3 ranks = one process"
}
lights lights-scanline
lights lights-interleaved --method raytrace --pattern interleaved
lights lights-hpc --method hpc
# The same scene with a textured light (the PNG just written as its texture): 2 ranks = one process; ranks
# given the scene with and without the texture (same geometry, other lights) refuse to run (exit 2, no output).
sed 's|"emission": \[3, 3, 3\] }|"emission": [3, 3, 3], "texture": "lights-scanline-1.png" }|' lights.json > lights-tex.json
check grep -q texture lights-tex.json
"$ms" lights-tex.json --threads 1 --quiet -o tex-1.exr
check test $? -eq 0
run -n 2 "$ms" lights-tex.json --threads 1 --quiet -o tex-2.exr
check test $? -eq 0
check cmp -s tex-1.exr tex-2.exr
check test -n "$(cmp lights-scanline-1.exr tex-1.exr)"   # the texture changed the image
run -n 1 "$ms" lights.json --threads 1 --quiet -o mixed.png : -n 1 "$ms" lights-tex.json --threads 1 --quiet -o mixed.png \
    2> mixed.err
check test $? -eq 2
check grep -q "different scenes or options" mixed.err
check test ! -e mixed.png
echo "ok: a textured light over 2 ranks; ranks given other lights refuse"
# Ranks given the scene with another material colour (same geometry and lights) refuse too.
sed 's/^Kd 0.8 0.3 0.1$/Kd 0.7 0.3 0.1/' m.mtl > m2.mtl
sed 's/^mtllib m.mtl$/mtllib m2.mtl/' m.obj > m2.obj
sed 's/"m.obj"/"m2.obj"/' lights.json > lights-mat.json
check test -n "$(cmp m.mtl m2.mtl)"
run -n 1 "$ms" lights.json --threads 1 --quiet -o mixed.png : -n 1 "$ms" lights-mat.json --threads 1 --quiet -o mixed.png \
    2> mixedmat.err
check test $? -eq 2
check grep -q "different scenes or options" mixedmat.err
check test ! -e mixed.png
echo "ok: ranks given other materials refuse"

# bake NAME ARGS... : a lightmap, one process against 2 and 3 ranks.
bake() {
    local name=$1; shift
    "$ms" bake "$@" --threads 1 --quiet -o "$name-1.exr" --png "$name-1.png" || { echo "FAIL: $name: single-process bake"; fail=1; return; }
    for r in 2 3; do
        local sched=queue
        [ $r = 3 ] && sched=counter
        run -n $r "$ms" bake "$@" --threads 1 --quiet --mpi-schedule $sched --mpi-chunk 3 -o "$name-$r.exr" --png "$name-$r.png"
        check test $? -eq 0
        check cmp -s "$name-1.exr" "$name-$r.exr"
        check cmp -s "$name-1.png" "$name-$r.png"
    done
    echo "ok: bake $name: 2 and 3 ranks = one process"
}
bake builtin --size 48 --samples 256
# Every light of the three-light scene (rect, disk, sphere) and the textured one: the EXR holds each light's
# S and V (S0.. V0..); and ranks given the scene with and without the texture refuse to bake.
bake lights lights.json --uv xatlas --size 24 --samples 256
bake lights-tex lights-tex.json --uv xatlas --size 24 --samples 256 --method raytrace
check test -n "$(cmp lights-1.exr lights-tex-1.exr)"
run -n 1 "$ms" bake lights.json --uv xatlas --size 16 --samples 256 --threads 1 --quiet -o mixed.exr : \
    -n 1 "$ms" bake lights-tex.json --uv xatlas --size 16 --samples 256 --threads 1 --quiet -o mixed.exr 2> mixedbake.err
check test $? -eq 2
check grep -q "different scenes or options" mixedbake.err
check test ! -e mixed.exr
if [ -f "$scenes/quad/quad.json" ]; then
    bake quad "$scenes/quad/quad.json" --uv xatlas --size 32 --samples 256
else
    echo "skipped: $scenes/quad absent (the shared scenes): no shared-scene bake"
fi

# A method that cannot be split is refused, not approximated.
run -n 2 "$ms" --width 32 --height 32 --samples 256 --threads 1 --method hpc-scanline -o refused.png 2> refused.err
check test $? -eq 2
check grep -q "hpc-scanline' cannot be split" refused.err
check test ! -e refused.png

# One rank cannot read its scene: exit 2, its one line, no outputs (nor staging files).
mkdir out
run -n 1 "$ms" --width 32 --height 32 --threads 1 --quiet -o out/x.png --vis out/x.pfm : \
    -n 1 "$ms" "$tmp/no-such-scene.json" --width 32 --height 32 --threads 1 --quiet -o out/x.png --vis out/x.pfm 2> bad.err
check test $? -eq 2
check test "$(wc -l < bad.err)" -eq 1
check grep -q "^microshadow: $tmp/no-such-scene.json: " bad.err
check test -z "$(ls -A out)"
run -n 2 "$ms" bake "$tmp/no-such-scene.json" --size 16 --threads 1 --quiet -o out/x.exr 2> badbake.err
check test $? -eq 2
check test "$(wc -l < badbake.err)" -eq 1
check test -z "$(ls -A out)"
echo "ok: refusals and a failing rank"
[ $fail = 0 ] && echo "test_mpi: all passed"
exit $fail
