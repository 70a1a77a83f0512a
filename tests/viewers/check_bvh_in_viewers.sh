#!/usr/bin/env bash
# Opens what `duet follow -o PARTNER.bvh --user-output USER.bvh` writes in the real viewers and
# checks that both dancers are where duet puts them: Blender's BVH importer (headless) and
# three.js's BVHLoader (Node). CTest: bvh_output_in_blender_and_threejs.
#   tests/viewers/check_bvh_in_viewers.sh DUET VIEWER_REFERENCE DATA_DIR [BLENDER] [NODE]
# 1. a 6 s improvised performance of salsa take 01 (leader 60_01, partner 61_01, 60 Hz; the user
#    turned by 120 degrees and moved 2 m in the room, sensor noise), followed against that duet;
# 2. viewer_reference: duet's own world positions of every joint at the checked frames (the user's
#    from the performance file itself) and the contact frames with the captured hand distances;
# 3. blender_import_check.py and web/tests/bvh-loader-check.mjs compare the viewers' positions
#    with them (1 mm) and check frame count, frame rate, the couple's spacing and held hands;
# 4. the checks must fail on a partner file whose root was moved 0.5 m (twice: against the
#    unmoved reference, and against a reference of the moved file, where only the held-hands
#    check can see it).
# Exit 77 (CTest: skipped) when the salsa data is missing. Keeps its files in a temporary
# directory; set DUET_VIEWER_CHECK_KEEP=DIR to keep them (and the two reports) in DIR instead.
set -euo pipefail
duet=$1
reference=$2
data=$3
blender=${4:-blender}
node=${5:-node}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
salsa="$data/cmu-salsa/bvh"
leader="$salsa/60/60_01_scaled.bvh"
follower="$salsa/61/61_01_scaled.bvh"
if [ ! -f "$leader" ] || [ ! -f "$follower" ]; then
  echo "check_bvh_in_viewers: no salsa take 01 under $salsa: skipped" >&2
  exit 77
fi

if [ -n "${DUET_VIEWER_CHECK_KEEP:-}" ]; then
  work=$DUET_VIEWER_CHECK_KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi

if [ ! -f "$root/web/node_modules/three/examples/jsm/loaders/BVHLoader.js" ]; then
  (cd "$root/web" && npm ci --no-audit --no-fund --prefer-offline >/dev/null)
fi

pair=(--pair "$leader" "$follower")
"$duet" improvise "${pair[@]}" --take 0 --fps 60 --duration 6 --seed 3 --noise-deg 2 \
  --noise-cm 1 --room-yaw 120 --room-offset 2 -1 -o "$work/performance.bvh" \
  --truth "$work/truth.csv"
"$duet" follow "${pair[@]}" --fps 60 --input "$work/performance.bvh" --trace "$work/trace.csv" \
  -o "$work/partner.bvh" --user-output "$work/user.bvh" 2>/dev/null
"$duet" contacts "$leader" "$follower" --fps 60 --json >"$work/contacts.json"

make_reference() {  # PARTNER.bvh OUT.json
  "$reference" --user "$work/user.bvh" --partner "$1" --input "$work/performance.bvh" \
    --trace "$work/trace.csv" --leader "$leader" --follower "$follower" \
    --contacts "$work/contacts.json" --out "$2"
}
check_blender() {  # PARTNER.bvh REFERENCE.json [REPORT.json]
  local rc=0
  "$blender" -b --factory-startup --python-exit-code 1 \
    --python "$root/tests/viewers/blender_import_check.py" -- --user "$work/user.bvh" \
    --partner "$1" --reference "$2" ${3:+--report "$3"} >"$work/blender.log" 2>&1 || rc=$?
  # Blender's own chatter (import timings) is left in blender.log.
  grep -E '^blender_import_check|Error|Traceback|^  File' "$work/blender.log" || true
  [ $rc -eq 0 ] || echo "check_bvh_in_viewers: blender exited with $rc (log: $work/blender.log)" >&2
  return $rc
}
check_three() {  # PARTNER.bvh REFERENCE.json [REPORT.json]
  "$node" "$root/web/tests/bvh-loader-check.mjs" --user "$work/user.bvh" --partner "$1" \
    --reference "$2" ${3:+--report "$3"}
}

make_reference "$work/partner.bvh" "$work/reference.json"
status=0
check_blender "$work/partner.bvh" "$work/reference.json" "$work/blender-report.json" || status=1
check_three "$work/partner.bvh" "$work/reference.json" "$work/three-report.json" || status=1
if [ $status -ne 0 ]; then
  echo "check_bvh_in_viewers: FAILED (files in $work)" >&2
  exit 1
fi

# The checks can fail: move the partner's root 0.5 m along x in every frame (the root's first
# channel is Xposition).
awk 'motion && NF > 0 { $1 = sprintf("%.6f", $1 + 0.5) } /^Frame Time:/ { motion = 1 } { print }' \
  "$work/partner.bvh" >"$work/partner-moved.bvh"
make_reference "$work/partner-moved.bvh" "$work/reference-moved.json" >/dev/null
for viewer in blender three; do
  if "check_$viewer" "$work/partner-moved.bvh" "$work/reference.json" >"$work/out.txt" 2>&1; then
    cat "$work/out.txt"
    echo "check_bvh_in_viewers: $viewer accepted a partner moved by 0.5 m" >&2
    status=1
  fi
  if "check_$viewer" "$work/partner-moved.bvh" "$work/reference-moved.json" >"$work/out.txt" 2>&1 ||
      ! grep -q "contact frame" "$work/out.txt"; then
    cat "$work/out.txt"
    echo "check_bvh_in_viewers: $viewer did not see the held hands apart in a partner moved" \
         "by 0.5 m" >&2
    status=1
  fi
done
if [ $status -ne 0 ]; then exit 1; fi
echo "check_bvh_in_viewers: Blender and three.js show both dancers where duet puts them; a" \
     "partner moved by 0.5 m is rejected by both"
