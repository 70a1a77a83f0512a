#!/usr/bin/env bash
# The main job: an improvised performance of salsa take 03 (segments in another order, pauses
# before jumps, sensor noise), followed against the whole library of 14 salsa duets. Writes the
# partner's motion (and the user's, in the same world frame) and prints an accuracy summary.
# Usage: scripts/demo.sh [DATA_DIR]   Output: out/
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
data_dir=${1:-$(scripts/get-data.sh)}
duet=build/apps/duet/duet
salsa="$data_dir/cmu-salsa/bvh"
mkdir -p out
if [ ! -d "$salsa" ]; then
  # Downloaded CMU originals only (ASF + AMC): describe one take.
  "$duet" inspect --fps 60 "$data_dir/cmu-salsa/asf-amc/60.asf" "$data_dir/cmu-salsa/asf-amc/60_01.amc"
  exit 0
fi
pairs=()
for trial in 01 02 03 04 05 06 07 09 10 11 12 13 14 15; do
  pairs+=(--pair "$salsa/60/60_${trial}_scaled.bvh" "$salsa/61/61_${trial}_scaled.bvh")
done
# Take 03 is the third pair in the list: its truth rows say take 2.
"$duet" improvise "${pairs[@]}" --take 2 --fps 60 --noise-deg 2 --noise-cm 1 --seed 7 \
  -o out/performance.bvh --truth out/truth.csv
"$duet" follow "${pairs[@]}" --fps 60 --input out/performance.bvh --input-fps 60 \
  --truth out/truth.csv --trace out/trace.csv -o out/partner.bvh --user-output out/user.bvh
echo "partner motion: out/partner.bvh (with the user in out/user.bvh); per-frame trace: out/trace.csv" >&2
