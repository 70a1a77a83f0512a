#!/usr/bin/env bash
# Browser test of the viewer against a real `duet serve`: starts the server with a looping replay
# of a salsa take on a free loopback port, then runs web/tests (headless Chromium, playwright-core)
# with DUET_VIEWER_URL pointing at it.
#   tests/browser/viewer_against_serve.sh DUET_BINARY DATA_DIR
set -euo pipefail
duet=$1
data=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
salsa="$data/cmu-salsa/bvh"

# Build the viewer first: the server serves web/dist.
(cd "$root/web" && npm ci --no-audit --no-fund --prefer-offline >/dev/null && npm run build >/dev/null)

port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log=$(mktemp)
"$duet" serve --pair "$salsa/60/60_03_scaled.bvh" "$salsa/61/61_03_scaled.bvh" --fps 60 \
  --source "replay:$salsa/60/60_03_scaled.bvh?loop=1" --http "127.0.0.1:$port" \
  --web "$root/web/dist" --no-record >"$log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null; rm -f "$log"' EXIT
for _ in $(seq 1 100); do
  if curl -fs "http://127.0.0.1:$port/" >/dev/null 2>&1; then break; fi
  if ! kill -0 $server 2>/dev/null; then cat "$log"; echo "duet serve exited" >&2; exit 1; fi
  sleep 0.2
done
DUET_VIEWER_URL="http://127.0.0.1:$port/" DUET_SKIP_NPM_CI=1 "$root/web/tests/run-browser-tests.sh"
