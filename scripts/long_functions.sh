#!/bin/sh
# Lists the C functions longer than MAX lines (default 150) under the given paths (default src/), longest
# first: "lines file:first_line name". Universal Ctags gives each function's first and last line (macro-named
# instances such as MS_KFN(...) are listed under the macro's name). Usage: scripts/long_functions.sh [MAX] [PATH...]
set -eu
max=${1:-150}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- src
ctags -R --languages=C --langmap=C:.c.h --kinds-C=f --fields=+ne -f - "$@" |
awk -v max="$max" -F'\t' '{
    s = ""; e = ""
    for (i = 4; i <= NF; i++) { if ($i ~ /^line:/) s = substr($i, 6); if ($i ~ /^end:/) e = substr($i, 5) }
    if (s != "" && e != "" && e - s + 1 > max) print e - s + 1, $2 ":" s, $1
}' | sort -rn
