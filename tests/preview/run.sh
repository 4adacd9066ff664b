#!/usr/bin/env bash
# Runs a browser test of the preview page (preview_test.mjs, or the script
# named first: run.sh haproxy_test.mjs ...): installs playwright-core (pinned
# by package-lock.json, into tests/preview/node_modules, never a browser) if
# it is not there yet, then drives Debian's /usr/bin/chromium.
# Missing node, npm or chromium is a failure, not a skip.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
for tool in node npm; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (scripts/install-deps.sh)" >&2; exit 1; }
done
if [ ! -f "$here/node_modules/playwright-core/package.json" ]; then
  # PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD: playwright-core downloads nothing, but be explicit.
  (cd "$here" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
fi
script=preview_test.mjs
if [[ "${1:-}" == *.mjs ]]; then script="$1"; shift; fi
exec node "$here/$script" "$@"
