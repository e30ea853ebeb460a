#!/usr/bin/env bash
# Renders every shipped scene into assets/gallery/ as a small PNG for the README, 256 pixels
# wide at the scene's own aspect ratio (a frame series renders frame 0; metals.ron in spectral
# transport).
# Usage: scripts/gallery.sh [WIDTH] [SPP]   (defaults: 256, each scene's own spp)
set -euo pipefail
cd "$(dirname "$0")/.."
width=${1:-256}
spp=${2:-}
cargo build --release --quiet
mkdir -p assets/gallery
for scene in scenes/*.ron; do
    name=$(basename "$scene" .ron)
    size=$(./target/release/prism info "$scene" | sed -n 's/^render: \([0-9]*\)x\([0-9]*\),.*/\1 \2/p')
    read -r w h <<<"$size"
    args=(render "$scene" -o "assets/gallery/$name.png" --size "${width}x$((h * width / w))" --quiet)
    [ -n "$spp" ] && args+=(--spp "$spp")
    # Measured metals show their spectral colour only in spectral transport.
    [ "$name" = metals ] && args+=(--force spectral)
    ./target/release/prism "${args[@]}"
    echo "assets/gallery/$name.png"
done
