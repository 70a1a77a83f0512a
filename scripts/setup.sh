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
scripts/demo.sh "$data_dir"
