#!/usr/bin/env bash
# Renders every shared scene (and the built-in one) with every shadow method by two microshadow binaries
# and compares the outputs byte for byte (PNG, V and S as PFM): the proof that a refactoring changed no
# image. Usage: scripts/compare_images.sh BASE_BINARY NEW_BINARY [SCENES_DIR] [OUT_DIR]
set -uo pipefail
base=${1:?usage: compare_images.sh BASE_BINARY NEW_BINARY [SCENES_DIR] [OUT_DIR]}
new=${2:?usage: compare_images.sh BASE_BINARY NEW_BINARY [SCENES_DIR] [OUT_DIR]}
scenes_dir=${3:-$(dirname "$0")/../../shared/scenes}
out=${4:-$(mktemp -d)}
methods=(scanline bounds hierarchical raytrace mft hpc hpc-scanline embree)
mkdir -p "$out"
same=0 differ=0 failed=0
scenes=("" "$scenes_dir"/*/*.json)
for scene in "${scenes[@]}"; do
    name=$(basename "${scene:-builtin}" .json)
    for m in "${methods[@]}"; do
        size=128
        [[ $m == hpc* ]] && size=96
        for who in base new; do
            bin=$base; [[ $who == new ]] && bin=$new
            if ! "$bin" $scene --method "$m" --width $size --height $size --samples 256 --threads 2 --quiet \
                -o "$out/$name.$m.$who.png" --vis "$out/$name.$m.$who.vis.pfm" \
                --shadow "$out/$name.$m.$who.shadow.pfm" 2>"$out/$name.$m.$who.err"; then
                echo "FAILED: $who $name $m: $(head -1 "$out/$name.$m.$who.err")"; failed=$((failed + 1))
            fi
        done
        for kind in png vis.pfm shadow.pfm; do
            if cmp -s "$out/$name.$m.base.$kind" "$out/$name.$m.new.$kind"; then same=$((same + 1))
            else echo "DIFFERENT: $name $m $kind"; differ=$((differ + 1)); fi
        done
    done
done
echo "compare_images: $same identical, $differ different, $failed failed runs (outputs in $out)"
[[ $differ == 0 && $failed == 0 ]]
