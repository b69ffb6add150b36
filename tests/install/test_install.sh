#!/usr/bin/env bash
# Installs the build into a fresh prefix inside the build tree, then builds and runs a small C program
# against the installed package both ways, find_package (shared and static) and pkg-config (shared and
# --static), a C++-only project with find_package, and runs the installed CLI.
# Usage: test_install.sh BUILD_DIR CC "EXTRA_FLAGS" CXX
set -euo pipefail
build=$(cd "$1" && pwd)
cc=$2
flags=$3
cxx=$4
src=$(cd "$(dirname "$0")" && pwd)
work=$build/tests/install-test
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.log"
libdir=$(dirname "$(find "$prefix" -name libmicroshadow.a | head -1)")
for f in "$prefix/include/microshadow.h" "$prefix/include/microshadow/render.h" "$prefix/include/microshadow_version.h" "$prefix/share/doc/microshadow/LICENSE" "$libdir/libmicroshadow.a" "$libdir/libmicroshadow.so" \
         "$prefix/bin/microshadow" "$libdir/cmake/microshadow/microshadowConfig.cmake" \
         "$libdir/pkgconfig/microshadow.pc" "$libdir/pkgconfig/microshadow-static.pc"; do
    [ -e "$f" ] || { echo "test_install: not installed: ${f#"$prefix"/}"; exit 1; }
done
echo "installed under $prefix"

echo "--- find_package"
CC=$cc cmake -S "$src/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" >"$work/consumer-configure.log" \
    || { cat "$work/consumer-configure.log"; exit 1; }
cmake --build "$work/consumer" -j 2 >"$work/consumer-build.log" || { cat "$work/consumer-build.log"; exit 1; }
"$work/consumer/consumer_shared"
"$work/consumer/consumer_static"
# the shared program really uses the installed library
# (ldd's output captured first: with pipefail, grep -q closing the pipe early would fail ldd with SIGPIPE)
deps=$(ldd "$work/consumer/consumer_shared")
grep -q "$libdir/libmicroshadow.so" <<<"$deps" \
    || { echo "test_install: consumer_shared does not load $libdir/libmicroshadow.so"; echo "$deps"; exit 1; }

echo "--- find_package from a C++-only project"
CXX=$cxx cmake -S "$src/consumer_cxx" -B "$work/consumer_cxx" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" >"$work/consumer-cxx-configure.log" \
    || { cat "$work/consumer-cxx-configure.log"; exit 1; }
cmake --build "$work/consumer_cxx" -j 2 >"$work/consumer-cxx-build.log" || { cat "$work/consumer-cxx-build.log"; exit 1; }
"$work/consumer_cxx/consumer_cxx_shared"
"$work/consumer_cxx/consumer_cxx_static"

echo "--- the installed shared library exports only the API"
bash "$src/../check_exports.sh" "$libdir/libmicroshadow.so" "$prefix/include/microshadow.h"

echo "--- pkg-config"
export PKG_CONFIG_PATH=$libdir/pkgconfig
# shellcheck disable=SC2046,SC2086
$cc $flags -o "$work/pc_shared" "$src/consumer/consumer.c" $(pkg-config --cflags --libs microshadow) -Wl,-rpath,"$libdir"
# shellcheck disable=SC2046,SC2086
$cc $flags -o "$work/pc_static" "$src/consumer/consumer.c" $(pkg-config --static --cflags --libs microshadow-static)
"$work/pc_shared"
"$work/pc_static"
deps=$(ldd "$work/pc_static")
! grep -q libmicroshadow <<<"$deps" || { echo "test_install: pc_static loads a shared microshadow"; exit 1; }

echo "--- the installed CLI"
"$prefix/bin/microshadow" --quiet --width 32 --height 24 --samples 256 -o "$work/cli.png"
[ -s "$work/cli.png" ] || { echo "test_install: the installed CLI wrote no image"; exit 1; }
echo "--- the installed Python module"
if [ -n "$flags" ]; then
    echo "skipped in a sanitized build (python is not instrumented; test_python covers the module there)"
elif ! /usr/bin/python3 -c "import numpy" 2>/dev/null; then
    echo "skipped: /usr/bin/python3 with numpy not found"
else
    (cd "$work" && env -u MICROSHADOW_LIBRARY PYTHONPATH="$libdir/python3/dist-packages" PYTHONDONTWRITEBYTECODE=1 \
        /usr/bin/python3 -c "
import microshadow as ms, numpy as np
assert ms._lib._name.startswith('$libdir/'), ms._lib._name
V, S = ms.visibility_points(ms.default_scene(), [[5, 0, 5], [2.25, 0.5, -0.75]], [[0, 1, 0], [0, 1, 0]])
assert V[0] == 1.0 and V[1] == 0.0, V
print('python: V', V, 'from', ms._lib._name)")
fi
echo "test_install: all passed"
