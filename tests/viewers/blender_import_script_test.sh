#!/usr/bin/env bash
# scripts/blender-import.py in headless Blender (CTest: blender_import_script): the partner and
# the user that `duet follow` wrote (salsa DAZ units) and a converted ASF+AMC take (CMU units,
# another frame rate) are imported into one scene, each at its true size: --check compares
# Blender's extent of every dancer over all frames with `duet inspect --json`'s (5 mm). The same
# files with a wrong --scale must fail the check.
#   tests/viewers/blender_import_script_test.sh DUET DATA_DIR BLENDER
set -uo pipefail
duet=$1
data=$2
blender=$3
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
cd "$tmp" || fail "cannot enter $tmp"

pair=(--pair "$data/cmu-salsa/bvh/60/60_01_scaled.bvh" "$data/cmu-salsa/bvh/61/61_01_scaled.bvh"
      --fps 60)
"$duet" improvise "${pair[@]}" --take 0 --duration 4 --seed 3 --room-yaw 120 --room-offset 2 -1 \
  -o perf.bvh >log 2>&1 || fail "improvise: $(cat log)"
"$duet" follow "${pair[@]}" --input perf.bvh -o partner.bvh --user-output user.bvh >log 2>&1 ||
  fail "follow: $(cat log)"
"$duet" convert "$data/cmu-salsa/asf-amc/60.asf" "$data/cmu-salsa/asf-amc/60_01.amc" \
  --input-fps 60 --fps 30 -o asf.bvh >log 2>&1 || fail "convert: $(cat log)"

run_blender() {  # OUT ARGS...: the script's arguments; Blender's output to OUT, its exit code back
  local out=$1
  shift
  "$blender" -b --factory-startup --python-exit-code 1 \
    --python "$root/scripts/blender-import.py" -- "$@" --duet "$duet" --check >"$out" 2>&1
}

run_blender good.log partner.bvh user.bvh asf.bvh ||
  fail "blender-import.py --check failed: $(grep -E 'blender-import|Error' good.log)"
grep 'blender-import' good.log
for expected in "partner.bvh -> armature 'partner', 240 frames at 60 fps, 1.30208 m per file unit" \
    "user.bvh -> armature 'user', 240 frames at 60 fps, 1.30208 m per file unit" \
    "asf.bvh -> armature 'asf', 1121 frames at 30 fps, 0.0564444 m per file unit" \
    "scene at 60 fps, frames 1-1121" "check passed"; do
  grep -qF "blender-import: $expected" good.log || fail "no '$expected' in: $(cat good.log)"
done

# The check can fail: metres instead of the salsa units make the dancers 1.3x too small.
if run_blender bad.log partner.bvh --scale 1; then
  fail "blender-import.py --check passed with a wrong --scale: $(grep blender-import bad.log)"
fi
grep -q "wrong scale?" bad.log || fail "no 'wrong scale?' in: $(cat bad.log)"
echo "blender_import_script: partner, user and an ASF conversion open at their true sizes"
