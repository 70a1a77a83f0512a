#!/usr/bin/env bash
# scripts/get-data.sh with no data anywhere and no network: it must fail fast (exit 1) and say
# which URLs to fetch and where to put them. Runs a copy of the script in an empty temporary
# project, so the real ../shared/data beside this project is not found; never touches the network
# (DUET_NO_DOWNLOAD, then a closed local port as the download URL).
set -uo pipefail
script=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/project/scripts" "$tmp/home"
cp "$script" "$tmp/project/scripts/get-data.sh"
fail() { echo "FAIL: $*" >&2; exit 1; }
run() {  # env assignments...: runs the copy, stdout+stderr to $tmp/out, exit code to $rc
  env -u DUET_DATA_DIR HOME="$tmp/home" "$@" timeout 60 bash "$tmp/project/scripts/get-data.sh" \
    > "$tmp/out" 2>&1
  rc=$?
}
expect_explained() {
  [ "$rc" -eq 1 ] || fail "$1: exit $rc, expected 1: $(cat "$tmp/out")"
  grep -q "$2/60/60.asf" "$tmp/out" || fail "$1: no URL of 60.asf in: $(cat "$tmp/out")"
  grep -q "$2/61/61_TRIAL.amc" "$tmp/out" || fail "$1: no AMC URL pattern in: $(cat "$tmp/out")"
  grep -q "$tmp/project/data/cmu-salsa/asf-amc/" "$tmp/out" || fail "$1: no target folder named"
  grep -q "DUET_DATA_DIR" "$tmp/out" || fail "$1: does not say how to point at a data directory"
}

run DUET_NO_DOWNLOAD=1
expect_explained "DUET_NO_DOWNLOAD" "http://mocap.cs.cmu.edu/subjects"

start=$(date +%s)
run DUET_DATA_URL=http://127.0.0.1:9 DUET_DOWNLOAD_TIMEOUT=2
expect_explained "unreachable server" "http://127.0.0.1:9"
grep -q "could not download http://127.0.0.1:9/60/60.asf" "$tmp/out" || fail "no failed URL named"
[ $(( $(date +%s) - start )) -lt 30 ] || fail "took more than 30 s without network"
[ -z "$(find "$tmp/project/data" -type f 2>/dev/null)" ] || fail "left files behind"

# A failed download must not count as data on the next run.
run DUET_NO_DOWNLOAD=1
expect_explained "after a failed download" "http://mocap.cs.cmu.edu/subjects"

# A DIR argument without the salsa data is an error that names it.
mkdir -p "$tmp/empty"
env -u DUET_DATA_DIR bash "$tmp/project/scripts/get-data.sh" "$tmp/empty" > "$tmp/out" 2>&1
rc=$?
[ "$rc" -eq 1 ] && grep -q "$tmp/empty" "$tmp/out" || fail "DIR without data: exit $rc"
echo "get-data.sh: explains and exits 1 without data and network"
