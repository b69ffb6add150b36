#!/usr/bin/env bash
# The folders of src/ depend on each other only downward (docs/design.md, "Layers"):
#   core <- light <- {accel, camera, raster, image} <- scene <- visibility <- {primary, shadow} <- render <- cli
# A subfolder (src/shadow/mft/, ...) belongs to its top-level folder's layer: it may include its own
# layer's headers (the layer's interface and, sideways, another family's shared part) and lower layers'.
# Includes across folders are written from src/ ("core/vec.h"; "../core/vec.h" is read the same way),
# same-folder includes by bare name. A file may include headers of its own layer and of lower layers
# only; the CLI only the public API. Fails, naming the offending #include, on a dependency that goes up
# or sideways between layers, and on any cycle between folders (subfolders counted as folders).
set -euo pipefail
src=${1:?usage: check_layers.sh SRC_DIR}
declare -A rank=([core]=0 [light]=1 [accel]=2 [camera]=2 [raster]=2 [image]=2 [scene]=3 [visibility]=4
                 [primary]=5 [shadow]=5 [render]=6 [cli]=7)
bad=0
edges=""
while IFS= read -r -d '' f; do
    rel=${f#"$src"/}
    folder=$(dirname "$rel")            # e.g. shadow/mft
    from=${folder%%/*}                  # its layer: shadow
    [[ $folder == . ]] && { echo "check_layers: $f: a file directly in src/ has no layer"; bad=1; continue; }
    [[ -n ${rank[$from]+x} ]] || { echo "check_layers: $f: folder '$from' has no layer (add it to tests/check_layers.sh and docs/design.md)"; bad=1; continue; }
    while IFS= read -r inc; do
        case $inc in
            microshadow.h|*.inc) continue ;;
            ../*/*) path=${inc#../}; [[ $folder == */* ]] && { echo "check_layers: $f includes \"$inc\": from a subfolder, include from src/"; bad=1; continue; } ;;
            */*) path=$inc ;;
            *) continue ;;   # same folder
        esac
        to_folder=$(dirname "$path")
        to=${path%%/*}
        [[ $to_folder == "$folder" ]] && continue
        edges+="$to_folder $folder"$'\n'
        [[ $to == "$from" ]] && continue
        if [[ $from == cli ]]; then
            echo "check_layers: $f includes \"$inc\": the CLI uses only the public API (microshadow.h)"; bad=1
        elif [[ -z ${rank[$to]+x} ]]; then
            echo "check_layers: $f includes \"$inc\": unknown folder '$to' (includes across folders are written from src/)"; bad=1
        elif (( rank[$to] >= rank[$from] )); then
            echo "check_layers: $f includes \"$inc\": $from (layer ${rank[$from]}) may not depend on $to (layer ${rank[$to]})"; bad=1
        fi
    done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f")
done < <(find "$src" -mindepth 2 -type f \( -name '*.[ch]' -o -name '*.cpp' \) -print0 | sort -z)
# Independently of the layer table: the folder graph (subfolders included) must be acyclic.
if [[ -n $edges ]] && ! sort -u <<<"$edges" | sed '/^$/d' | tsort >/dev/null 2>/tmp/check_layers.$$; then
    echo "check_layers: the folders depend on each other in a cycle:"; cat /tmp/check_layers.$$; bad=1
fi
rm -f /tmp/check_layers.$$
[[ $bad == 0 ]] && echo "check_layers: $(sort -u <<<"$edges" | sed '/^$/d' | wc -l) folder dependencies, all downward, no cycle"
exit $bad
