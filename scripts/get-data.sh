#!/usr/bin/env bash
# Finds the CMU salsa motion data and prints its directory on stdout.
#
#   scripts/get-data.sh [DIR]
#
# Order: DIR (argument), then $DUET_DATA_DIR, then ../shared/data beside the project, then a
# previous download in data/. Otherwise downloads the CMU originals of the salsa pairs
# (subjects 60 and 61, ASF + AMC) from mocap.cs.cmu.edu into data/cmu-salsa/asf-amc/.
# The data: CMU Graphics Lab Motion Capture Database, mocap.cs.cmu.edu, created with funding
# from NSF EIA-0196217.
set -euo pipefail
project_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

has_salsa() { [ -d "$1/cmu-salsa" ]; }

for candidate in "${1:-}" "${DUET_DATA_DIR:-}" "$project_root/../shared/data" "$project_root/data"; do
  [ -n "$candidate" ] || continue
  if has_salsa "$candidate"; then
    (cd "$candidate" && pwd)
    exit 0
  fi
  if [ "$candidate" = "${1:-}" ] || [ "$candidate" = "${DUET_DATA_DIR:-}" ]; then
    echo "get-data: '$candidate' has no cmu-salsa/ folder" >&2
    exit 1
  fi
done

target="$project_root/data/cmu-salsa/asf-amc"
base_url="http://mocap.cs.cmu.edu/subjects"
trials="01 02 03 04 05 06 07 08 09 10 11 12 13 14 15"
echo "get-data: no local copy found; downloading the CMU salsa takes (subjects 60, 61) into $target" >&2
mkdir -p "$target"
fetch() {  # url file: download to a temporary name, then rename, so no half file is left
  local url=$1 out=$2
  [ -s "$out" ] && return 0
  if ! curl -fsSL --connect-timeout 10 --retry 2 -o "$out.part" "$url"; then
    rm -f "$out.part"
    echo "get-data: could not download $url (no network?). Give a data directory instead:" >&2
    echo "  scripts/get-data.sh /path/to/data   (a folder with cmu-salsa/ inside)" >&2
    exit 1
  fi
  mv "$out.part" "$out"
}
total=$((2 + 2 * 15))
count=0
for subject in 60 61; do
  fetch "$base_url/$subject/$subject.asf" "$target/$subject.asf"
  count=$((count + 1)); echo "get-data: $count/$total" >&2
  for trial in $trials; do
    fetch "$base_url/$subject/${subject}_${trial}.amc" "$target/${subject}_${trial}.amc"
    count=$((count + 1)); echo "get-data: $count/$total" >&2
  done
done
echo "$project_root/data"
