#!/usr/bin/env bash
# `cmake --install` into a temporary prefix: bin/duet runs, the viewer's files are installed when
# web/dist is built (and only then), and the installed `duet serve` finds them beside the binary.
#   tests/scripts/install_test.sh CMAKE BUILD_DIR SOURCE_DIR DATA_DIR
set -uo pipefail
cmake=$1
build=$2
source=$3
data=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
prefix="$tmp/prefix"

"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 ||
  fail "cmake --install failed: $(cat "$tmp/install.log")"
[ -x "$prefix/bin/duet" ] || fail "no $prefix/bin/duet after install: $(cat "$tmp/install.log")"
version=$("$prefix/bin/duet" --version) || fail "installed duet --version exited $?"
[[ "$version" == "duet "* ]] || fail "installed duet --version printed '$version'"

web="$prefix/share/duet/web"
if [ -f "$source/web/dist/index.html" ]; then
  [ -f "$web/index.html" ] || fail "web/dist is built but $web/index.html was not installed"
else
  [ ! -e "$web" ] || fail "web/dist is not built but $web was installed"
  mkdir -p "$web" && echo '<!doctype html><title>stub</title>' >"$web/index.html"
fi

# The installed server, started away from any web/dist, serves the installed viewer.
leader="$data/cmu-salsa/bvh/60/60_01_scaled.bvh"
partner="$data/cmu-salsa/bvh/61/61_01_scaled.bvh"
[ -f "$leader" ] && [ -f "$partner" ] || fail "no salsa take 01 under $data/cmu-salsa/bvh"
cd "$tmp" || fail "cannot enter $tmp"
pair=(--pair "$leader" "$partner" --fps 60)
"$prefix/bin/duet" improvise "${pair[@]}" --take 0 --duration 1 -o perf.bvh \
  >/dev/null 2>&1 || fail "improvise failed"
timeout 120 "$prefix/bin/duet" serve "${pair[@]}" --source 'replay:perf.bvh?loop=0' \
  --http 127.0.0.1:0 --exit-at-end --no-record >serve.out 2>serve.err ||
  fail "installed duet serve exited $?: $(cat serve.err)"
grep -qF "viewer files from $web" serve.err ||
  fail "installed duet serve did not serve $web: $(cat serve.err)"
echo "install_test: $prefix/bin/duet runs ($version) and serves $web"
