#!/usr/bin/env bash
# The Python package installs offline from Debian's pip and setuptools (no index, no build isolation),
# its version is CMake's project() version, and the installed copy imports and answers against the
# library given by MICROSHADOW_LIBRARY. Usage: test_package.sh PYTHON SOURCE_DIR VERSION WORK_DIR
set -euo pipefail
py=$1 src=$2 version=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
grep -q "^version = \"$version\"$" "$src/python/pyproject.toml" \
  || { echo "test_package: python/pyproject.toml's version is not project()'s $version"; exit 1; }
# built from a copy: setuptools writes build/ and *.egg-info next to the sources
cp -r "$src/python" "$work/src"
"$py" -m pip install --no-build-isolation --no-deps --no-index --quiet --disable-pip-version-check \
  --target "$work/site" "$work/src" >"$work/pip.log" 2>&1 || { cat "$work/pip.log"; exit 1; }
(cd "$work" && PYTHONPATH="$work/site" PYTHONDONTWRITEBYTECODE=1 "$py" -c "
import microshadow as ms, numpy as np
assert ms.__file__.startswith('$work/site/'), ms.__file__
assert ms.__version__ == '$version', ms.__version__
V, S = ms.visibility_points(ms.default_scene(), [[5, 0, 5], [2.25, 0.5, -0.75]], [[0, 1, 0], [0, 1, 0]])
assert V[0] == 1.0 and V[1] == 0.0, V
print('test_package: pip installed microshadow', ms.__version__, 'into', '$work/site')")
