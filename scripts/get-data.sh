#!/usr/bin/env bash
# Finds the CMU salsa motion data and prints its directory on stdout.
#
#   scripts/get-data.sh [DIR]
#
# Order: DIR (argument), then $DUET_DATA_DIR, then ../shared/data beside the project, then a
# previous download in data/. Otherwise downloads the CMU originals of the salsa pairs
# (subjects 60 and 61, ASF + AMC) from mocap.cs.cmu.edu into data/cmu-salsa/asf-amc/, which
# libraries/cmu-salsa-asf-amc.toml describes. When it cannot (DUET_NO_DOWNLOAD set, no curl, no
# network), it says which URLs to fetch and where to put them, and exits 1.
# Environment: DUET_DATA_DIR, DUET_NO_DOWNLOAD, DUET_DATA_URL (a mirror), DUET_DOWNLOAD_TIMEOUT
# (connect timeout, seconds).
# The data: CMU Graphics Lab Motion Capture Database, mocap.cs.cmu.edu, created with funding
# from NSF EIA-0196217.
set -euo pipefail
project_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# The BVH duets, or a complete set of CMU originals (a download writes 61_15.amc last; an
# interrupted one leaves no half file, see fetch).
has_salsa() { [ -d "$1/cmu-salsa/bvh" ] || [ -s "$1/cmu-salsa/asf-amc/61_15.amc" ]; }

for candidate in "${1:-}" "${DUET_DATA_DIR:-}" "$project_root/../shared/data" "$project_root/data"; do
  [ -n "$candidate" ] || continue
  if has_salsa "$candidate"; then
    (cd "$candidate" && pwd)
    exit 0
  fi
  if [ "$candidate" = "${1:-}" ] || [ "$candidate" = "${DUET_DATA_DIR:-}" ]; then
    echo "get-data: '$candidate' has no cmu-salsa/bvh/ nor a complete cmu-salsa/asf-amc/" >&2
    exit 1
  fi
done

target="$project_root/data/cmu-salsa/asf-amc"
# DUET_DATA_URL: a mirror with CMU's layout (SUBJECT/SUBJECT.asf, SUBJECT/SUBJECT_TRIAL.amc).
base_url="${DUET_DATA_URL:-http://mocap.cs.cmu.edu/subjects}"
trials="01 02 03 04 05 06 07 08 09 10 11 12 13 14 15"
# What to fetch by hand when this script cannot: the URLs, where they go, and the alternative.
explain() {
  echo "get-data: $1" >&2
  cat >&2 <<MSG
get-data: either point Duet at a data directory that has cmu-salsa/ inside:
  scripts/get-data.sh /path/to/data      or      export DUET_DATA_DIR=/path/to/data
or fetch the CMU originals of the salsa duets by hand into
  $target/
namely $base_url/60/60.asf, $base_url/61/61.asf and, for TRIAL in $trials,
  $base_url/60/60_TRIAL.amc and $base_url/61/61_TRIAL.amc
(e.g. $base_url/60/60_01.amc), then run scripts/get-data.sh again. The library file
libraries/cmu-salsa-asf-amc.toml describes them (--library libraries/cmu-salsa-asf-amc.toml --data-dir $project_root/data).
MSG
  exit 1
}
if [ -n "${DUET_NO_DOWNLOAD:-}" ]; then
  explain "no local copy of the salsa data found, and DUET_NO_DOWNLOAD is set"
fi
if ! command -v curl > /dev/null; then
  explain "no local copy of the salsa data found, and curl is not installed to download it"
fi
echo "get-data: no local copy found; downloading the CMU salsa takes (subjects 60, 61) into $target" >&2
mkdir -p "$target"
fetch() {  # url file: download to a temporary name, then rename, so no half file is left
  local url=$1 out=$2
  [ -s "$out" ] && return 0
  # Bounded: a dead network fails in seconds instead of hanging the setup.
  if ! curl -fsSL --connect-timeout "${DUET_DOWNLOAD_TIMEOUT:-10}" --max-time 300 --retry 1 \
      -o "$out.part" "$url"; then
    rm -f "$out.part"
    explain "could not download $url (no network?)"
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
