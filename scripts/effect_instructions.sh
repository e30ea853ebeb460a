#!/usr/bin/env bash
# Instructions per sample (valgrind's callgrind: a count, not a time, so it repeats exactly) of
# a scene with each effect it does not need forced on, against the scene as it is. The render
# runs twice per setting (4 and 12 spp, one thread) and the difference is divided by the
# extra samples, so loading and setup cancel. Width 8 (AVX2): valgrind has no AVX-512.
# Usage: scripts/effect_instructions.sh [SCENE]   (default: scenes/cornell.ron)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/cornell.ron}
command -v valgrind >/dev/null || { echo "valgrind is not installed: skipped"; exit 0; }
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
count() {
    valgrind --tool=callgrind --callgrind-out-file="$out/cg" ./target/release/prism render "$scene" \
        --simd 8 --threads 1 --spp "$1" --size 64x64 --quiet -o "$out/x.exr" "${@:2}" 2>&1 |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
per_sample() {
    local a b
    a=$(count 4 "$@")
    b=$(count 12 "$@")
    echo "($b - $a) / (8 * 64 * 64)" | bc -l
}
base=$(per_sample)
printf '| forced effect | instructions per sample | against none |\n|---|---|---|\n'
printf '| none | %.0f | 1.000× |\n' "$base"
for e in lens motion spectral media textures normal_maps; do
    if ./target/release/prism info "$scene" | grep -qi "^${e}: on"; then continue; fi
    n=$(per_sample --force "$e")
    printf '| %s | %.0f | %.3f× |\n' "$e" "$n" "$(echo "$n / $base" | bc -l)"
done
