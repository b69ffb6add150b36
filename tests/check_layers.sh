#!/usr/bin/env bash
# The folders of src/ depend on each other only downward (docs/design.md, "Layers"):
#   core <- {accel, camera, raster, image} <- scene <- shadow <- render <- cli
# A file may include headers of its own folder and of lower layers only; the CLI only the public API.
# Fails, naming the offending #include, on a dependency that goes up or sideways, and on any cycle.
set -euo pipefail
src=${1:?usage: check_layers.sh SRC_DIR}
declare -A rank=([core]=0 [accel]=1 [camera]=1 [raster]=1 [image]=1 [scene]=2 [shadow]=3 [render]=4 [cli]=5)
bad=0
edges=""
for f in "$src"/*/*.[ch]; do
    from=$(basename "$(dirname "$f")")
    [[ -n ${rank[$from]+x} ]] || { echo "check_layers: $f: folder '$from' has no layer (add it to tests/check_layers.sh and docs/design.md)"; bad=1; continue; }
    while IFS= read -r inc; do
        case $inc in
            microshadow.h|*.inc) continue ;;
            ../*/*) to=${inc#../}; to=${to%%/*} ;;
            */*) to=${inc%%/*} ;;
            *) continue ;;   # same folder
        esac
        [[ $to == "$from" ]] && continue
        edges+="$to $from"$'\n'
        if [[ $from == cli ]]; then
            echo "check_layers: $f includes \"$inc\": the CLI uses only the public API (microshadow.h)"; bad=1
        elif [[ -z ${rank[$to]+x} ]]; then
            echo "check_layers: $f includes \"$inc\": unknown folder '$to'"; bad=1
        elif (( rank[$to] >= rank[$from] )); then
            echo "check_layers: $f includes \"$inc\": $from (layer ${rank[$from]}) may not depend on $to (layer ${rank[$to]})"; bad=1
        fi
    done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f")
done
# Independently of the layer table: the folder graph must be acyclic.
if [[ -n $edges ]] && ! sort -u <<<"$edges" | sed '/^$/d' | tsort >/dev/null 2>/tmp/check_layers.$$; then
    echo "check_layers: the folders depend on each other in a cycle:"; cat /tmp/check_layers.$$; bad=1
fi
rm -f /tmp/check_layers.$$
[[ $bad == 0 ]] && echo "check_layers: $(sort -u <<<"$edges" | sed '/^$/d' | wc -l) folder dependencies, all downward, no cycle"
exit $bad
