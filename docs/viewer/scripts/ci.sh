#!/usr/bin/env bash
# The viewer's CI: Debian's Chromium, the pinned npm packages, the vendored
# three.js check, then the tests (node's test runner; they validate and
# screenshot a generated fixture and the repository's glTF scenes).
#   bash docs/viewer/scripts/ci.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x /usr/bin/chromium ]; then
	apt-get update -qq
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
npm ci --no-audit --no-fund
node scripts/vendor.mjs --check
node --test test/viewer.test.mjs
