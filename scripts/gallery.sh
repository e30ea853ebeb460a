#!/usr/bin/env bash
# Renders every shipped scene into assets/gallery/ as a small PNG for the README.
# Usage: scripts/gallery.sh [SIZE] [SPP]   (defaults: 256, each scene's own spp)
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-256}
spp=${2:-}
cargo build --release --quiet
mkdir -p assets/gallery
for scene in scenes/*.ron; do
    name=$(basename "$scene" .ron)
    args=(render "$scene" -o "assets/gallery/$name.png" --size "${size}x${size}" --quiet)
    [ -n "$spp" ] && args+=(--spp "$spp")
    ./target/release/prism "${args[@]}"
    echo "assets/gallery/$name.png"
done
