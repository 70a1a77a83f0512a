#!/usr/bin/env bash
# Installs the viewer's locked npm packages, builds web/dist, and runs the browser tests.
#
#   web/tests/run-browser-tests.sh                      # against tests/mock-server.mjs
#   DUET_VIEWER_URL=http://127.0.0.1:8080/ web/tests/run-browser-tests.sh   # a running duet serve
#
# Needs Node >= 20.19 with npm, and Debian's chromium (apt-get install -y chromium), or a
# Chromium at DUET_CHROMIUM. Set DUET_SKIP_NPM_CI=1 to reuse an existing node_modules.
set -euo pipefail

web_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$web_dir"

chromium="${DUET_CHROMIUM:-/usr/bin/chromium}"
if [[ ! -x "$chromium" ]]; then
  echo "run-browser-tests: no Chromium at $chromium (apt-get install -y chromium, or set DUET_CHROMIUM)" >&2
  exit 1
fi
if ! command -v npm >/dev/null; then
  echo "run-browser-tests: npm not found (install Node >= 20.19)" >&2
  exit 1
fi

if [[ "${DUET_SKIP_NPM_CI:-0}" != 1 || ! -d node_modules ]]; then
  # --prefer-offline: use the npm cache when it has the locked versions.
  npm ci --no-audit --no-fund --prefer-offline
fi
npm run build
if [[ -n "${DUET_VIEWER_URL:-}" ]]; then
  echo "run-browser-tests: testing the viewer served by $DUET_VIEWER_URL"
else
  echo "run-browser-tests: testing against the mock server"
fi
exec node --test tests/
