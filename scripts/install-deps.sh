#!/usr/bin/env bash
# Installs the Debian packages microshadow needs that are missing (root, or sudo when available).
set -euo pipefail
# clang, libclang-rt-dev (sanitizer and libFuzzer runtimes) and libomp-dev (OpenMP for clang): the clang
# build and the fuzzers of .ci/run. python3-numpy: the Python module's tests (python/, run by ctest); python3-pip
# and python3-setuptools: its package (python/pyproject.toml) installed offline by test_python_package.
# libopenmpi-dev and openmpi-bin: the CLI's optional MPI mode (-DMS_MPI=ON; .ci/run builds and tests it).
# nodejs, npm and chromium: the baked glTF's tests (the Khronos validator, the three.js viewer in headless
# chromium); their npm packages (viewer/package.json: three, gltf-validator, puppeteer-core) go into
# viewer/node_modules, never committed. libzstd-dev: KTX2 textures with Zstandard supercompression.
# libwebp-dev: WebP textures (EXT_texture_webp). libmeshoptimizer-dev and libdraco-dev: glTF buffer views with
# EXT_meshopt_compression and primitives with KHR_draco_mesh_compression. blender: the Blender add-on's test
# (blender/, tests/blender; headless, with Cycles as the light units' reference). lld: the sanitized test
# build links its test programs with it (CMakeLists.txt; GNU ld when it is absent).
pkgs=(build-essential cmake pkg-config libcjson-dev libpng-dev libturbojpeg0-dev libzstd-dev libwebp-dev
      libmeshoptimizer-dev libdraco-dev libopenexr-dev libembree-dev libcmocka-dev gnuplot-nox clang lld
      libclang-rt-dev libomp-dev python3-numpy python3-pip python3-setuptools libopenmpi-dev openmpi-bin nodejs
      npm chromium blender)
missing=()
for p in "${pkgs[@]}"; do
  # Node.js from elsewhere (e.g. NodeSource's nodejs, which bundles npm and conflicts with Debian's npm
  # package): its commands are what the tests need, not Debian's packages.
  case $p in nodejs) command -v node >/dev/null && continue ;; npm) command -v npm >/dev/null && continue ;; esac
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# The viewer's npm packages, pinned by viewer/package-lock.json (skipped offline: those tests then skip).
viewer="$(cd "$(dirname "$0")/.." && pwd)/viewer"
if command -v npm >/dev/null && [ ! -d "$viewer/node_modules/gltf-validator" ]; then
  (cd "$viewer" && npm ci --no-audit --no-fund) || echo "install-deps: npm ci in $viewer failed: the glTF validator and viewer tests will skip" >&2
fi
