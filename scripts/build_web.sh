#!/usr/bin/env bash
# Builds the viewer's web page (docs/viewer.md) into build/web: index.html, viewer.js (one
# minified ES module with three.js and roslib in it) and viewer.css; and the annotation tool's
# page (docs/annotation.md): annotate.html, annotate.js and annotate.css. Everything the page needs
# is in that folder: nothing is fetched from a CDN at run time.
# Usage: bash scripts/build_web.sh   (needs node and npm; scripts/setup.sh installs them)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${PARTSIM_WEB_OUT:-build/web}"

# packages: exactly the lock's versions when there is one (and node_modules is not current)
if [ -f web/package-lock.json ]; then
  if [ ! -f web/node_modules/.package-lock.json ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then
    npm ci --prefix web --no-audit --no-fund
  fi
else
  npm install --prefix web --no-audit --no-fund
fi

mkdir -p "$out"
# roslib imports the 'ws' package only where there is no WebSocket (Node): a stub stands in
web/node_modules/.bin/esbuild web/src/main.js --bundle --minify --format=esm --platform=browser \
  --target=es2022 --alias:ws=./web/src/no_ws.js --legal-comments=eof --log-level=warning --outfile="$out/viewer.js"
cp web/index.html web/viewer.css "$out/"
# the annotation page of `partsim annotate` (docs/annotation.md)
web/node_modules/.bin/esbuild web/src/annotate.js --bundle --minify --format=esm --platform=browser \
  --target=es2022 --alias:ws=./web/src/no_ws.js --legal-comments=eof --log-level=warning --outfile="$out/annotate.js"
cp web/annotate.html web/annotate.css "$out/"
echo "partsim: web page built in $out ($(du -k "$out/viewer.js" | cut -f1) KiB of script)"
