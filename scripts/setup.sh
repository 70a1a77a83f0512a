#!/usr/bin/env bash
# One command for a new user: install dependencies, build, find or fetch the data, run the
# main job. Usage: scripts/setup.sh [DATA_DIR]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/install-deps.sh
data_dir=$(scripts/get-data.sh "${1:-}")
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DDUET_DATA_DIR="$data_dir" >/dev/null
cmake --build build -j"$(nproc)"
echo "== duet is built: build/apps/duet/duet" >&2
if command -v npm >/dev/null; then
  (cd web && npm ci --no-audit --no-fund --prefer-offline >/dev/null && npm run build >/dev/null) &&
    echo "== the viewer is built: web/dist (served by duet serve)" >&2
else
  echo "== npm not found: the browser viewer (web/) is not built" >&2
fi
# Install (after the viewer, so its files go along): the prefix is ~/.local unless the build was
# configured with another CMAKE_INSTALL_PREFIX.
cmake --install build >/dev/null
prefix=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' build/CMakeCache.txt)
echo "== duet is installed: $prefix/bin/duet" >&2
case ":$PATH:" in
  *":$prefix/bin:"*) echo "== $prefix/bin is on your PATH: run duet --help" >&2 ;;
  *) echo "== $prefix/bin is not on your PATH: add it (e.g. to ~/.profile):" \
       "export PATH=\"$prefix/bin:\$PATH\"" >&2 ;;
esac
scripts/demo.sh "$data_dir"
