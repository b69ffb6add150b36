#!/usr/bin/env bash
# The shared library exports exactly the API: every dynamic symbol it defines is an ms_ function declared
# MS_API in the header, and every MS_API declaration is defined (a declared function that is missing would
# fail only in a consumer's link). The header is read with its parts, the microshadow/*.h beside it.
# Usage: check_exports.sh LIBRARY.so include/microshadow.h
set -euo pipefail
lib=${1:?usage: check_exports.sh LIBRARY.so HEADER}
header=${2:?usage: check_exports.sh LIBRARY.so HEADER}
parts=("$(dirname "$header")"/microshadow/*.h)
[ -e "${parts[0]}" ] || { echo "check_exports: no parts beside $header (microshadow/*.h)"; exit 1; }
# The names the header and its parts declare MS_API (one declaration starts per line): functions, and
# data (an array, `name[]`).
declared=$(sed -n -e 's/^MS_API .*\b\(ms_[a-z0-9_]*\)(.*/\1/p' -e 's/^MS_API extern .*\b\(ms_[a-z0-9_]*\)\[\];.*/\1/p' \
    "$header" "${parts[@]}" | sort -u)
[ -n "$declared" ] || { echo "check_exports: no MS_API declaration found in $header"; exit 1; }
# Every defined dynamic symbol, of any kind (functions, data, weak, unique, absolute).
exported=$(nm -D --defined-only "$lib" | awk '{print $NF}' | sed 's/@.*//' | sort -u)
bad=0
while IFS= read -r s; do
    [ -z "$s" ] && continue
    if ! grep -qx -- "$s" <<<"$declared"; then
        echo "check_exports: $lib exports '$s', which is not an MS_API declaration of $header"; bad=1
    fi
done <<<"$exported"
while IFS= read -r s; do
    grep -qx -- "$s" <<<"$exported" || { echo "check_exports: $header declares '$s', which $lib does not export"; bad=1; }
done <<<"$declared"
[ $bad = 0 ] && echo "check_exports: $(wc -l <<<"$exported") symbols exported, all of them the API ($(wc -l <<<"$declared") MS_API declarations)"
exit $bad
