#!/usr/bin/env bash
# The main job: an improvised performance of salsa take 03 (segments in another order, pauses
# before jumps, sensor noise), followed against the whole library of 14 salsa duets. Writes the
# partner's motion (and the user's, in the same world frame) and prints an accuracy summary.
# Usage: scripts/demo.sh [DATA_DIR]   Output: out/
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
data_dir=${1:-$(scripts/get-data.sh)}
duet=build/apps/duet/duet
mkdir -p out
# The library file: the BVH duets, or the CMU originals (ASF + AMC) that get-data.sh downloads.
library=libraries/cmu-salsa.toml
if [ ! -d "$data_dir/cmu-salsa/bvh" ]; then
  library=libraries/cmu-salsa-asf-amc.toml
fi
lib=(--library "$library" --data-dir "$data_dir")
# Take 03 is the third pair in the library: its truth rows say take 2. The library file sets
# the salsa frame rate (60 fps; the BVH headers say 120).
"$duet" improvise "${lib[@]}" --take 2 --noise-deg 2 --noise-cm 1 --seed 7 \
  -o out/performance.bvh --truth out/truth.csv
"$duet" follow "${lib[@]}" --input out/performance.bvh --input-fps 60 \
  --truth out/truth.csv --trace out/trace.csv -o out/partner.bvh --user-output out/user.bvh
echo "partner motion: out/partner.bvh (with the user in out/user.bvh); per-frame trace: out/trace.csv" >&2
