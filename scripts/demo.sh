#!/usr/bin/env bash
# The main job: describe one salsa pair (the leader and the partner of take 01).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
data_dir=${1:-$(scripts/get-data.sh)}
duet=build/apps/duet/duet
if [ -f "$data_dir/cmu-salsa/bvh/60/60_01_scaled.bvh" ]; then
  "$duet" inspect --fps 60 "$data_dir/cmu-salsa/bvh/60/60_01_scaled.bvh"
  "$duet" inspect --fps 60 "$data_dir/cmu-salsa/bvh/61/61_01_scaled.bvh"
else
  "$duet" inspect --fps 60 "$data_dir/cmu-salsa/asf-amc/60.asf" "$data_dir/cmu-salsa/asf-amc/60_01.amc"
fi
