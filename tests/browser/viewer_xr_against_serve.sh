#!/usr/bin/env bash
# Browser test of the headset path (issue 12): `duet serve --source xr` with the salsa library,
# a three-point recording of take 60_07 made by `duet convert --points head,hands` with the
# devices where a headset user's sit (the server's default --device-offsets-cm 6,6,7), and the
# viewer in headless Chromium with the emulated headset (?xr-emulate=1) playing the recording
# as the headset's and controllers' poses (web/tests/xr_headset.test.mjs).
#   tests/browser/viewer_xr_against_serve.sh DUET_BINARY DATA_DIR
set -euo pipefail
duet=$1
data=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)

# Build the viewer first: the server serves web/dist.
(cd "$root/web" && npm ci --no-audit --no-fund --prefer-offline >/dev/null && npm run build >/dev/null)

work=$(mktemp -d)
server=
cleanup() {
  if [[ -n "$server" ]]; then kill "$server" 2>/dev/null || true; wait "$server" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

recording="$work/60_07_points.csv"
"$duet" convert "$data/cmu-salsa/bvh/60/60_07_scaled.bvh" --input-fps 60 --points head,hands \
  --device-offsets-cm 6,6,7 -o "$recording" >/dev/null

port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log="$work/serve.log"
"$duet" serve --library "$root/libraries/cmu-salsa.toml" --data-dir "$data" --source xr \
  --http "127.0.0.1:$port" --web "$root/web/dist" --no-record >"$log" 2>&1 &
server=$!
# The library's models take a while to build before the server listens.
for _ in $(seq 1 600); do
  if curl -fs "http://127.0.0.1:$port/" >/dev/null 2>&1; then break; fi
  if ! kill -0 "$server" 2>/dev/null; then cat "$log"; echo "duet serve exited" >&2; exit 1; fi
  sleep 0.2
done

cd "$root/web"
status=0
DUET_VIEWER_URL="http://127.0.0.1:$port/" DUET_XR_RECORDING="$recording" \
  node --test tests/xr_headset.test.mjs || status=$?
if [[ $status -ne 0 ]]; then
  echo "--- duet serve log ---"
  tail -n 40 "$log"
fi
exit $status
