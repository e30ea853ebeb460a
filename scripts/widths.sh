#!/usr/bin/env bash
# Whole-process render time of every shipped scene at each lane width this CPU runs natively,
# in alternating runs, and the median per width; the images are compared with width 1's.
# Usage: scripts/widths.sh [RUNS] [SPP] [SIZE]   (defaults: 3, 16, 256x256)
# Prints a Markdown table: scene, seconds per width, speed-ups against width 1, and the
# relMSE of each wider image against width 1's.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
spp=${2:-16}
size=${3:-256x256}
cargo build --release --quiet
bin=./target/release/prism
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
widths=(1)
for w in 8 16; do
    if $bin render scenes/cornell.ron --simd "$w" --spp 1 --size 8x8 --quiet -o "$out/probe.exr" 2>/dev/null; then
        widths+=("$w")
    fi
done
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
header="| scene |"
rule="|---|"
for w in "${widths[@]}"; do header+=" width $w (s) |"; rule+="---|"; done
for w in "${widths[@]:1}"; do header+=" $w vs 1 |"; rule+="---|"; done
for w in "${widths[@]:1}"; do header+=" relMSE $w vs 1 |"; rule+="---|"; done
echo "$header"
echo "$rule"
for scene in scenes/*.ron; do
    name=$(basename "$scene" .ron)
    declare -A times=()
    for ((r = 0; r < runs; r++)); do
        for w in "${widths[@]}"; do
            t0=$(date +%s.%N)
            $bin render "$scene" --spp "$spp" --size "$size" --simd "$w" --quiet -o "$out/$name-$w.exr"
            t1=$(date +%s.%N)
            times[$w]+="$(echo "$t1 - $t0" | bc) "
        done
    done
    row="| $name |"
    declare -A med=()
    for w in "${widths[@]}"; do
        med[$w]=$(tr ' ' '\n' <<<"${times[$w]}" | grep . | median)
        row+=" $(printf '%.2f' "${med[$w]}") |"
    done
    for w in "${widths[@]:1}"; do row+=" $(echo "scale=2; ${med[1]} / ${med[$w]}" | bc)× |"; done
    for w in "${widths[@]:1}"; do
        rel=$($bin compare "$out/$name-$w.exr" "$out/$name-1.exr" | sed -n 's/.*relMSE: \([^ ]*\).*/\1/p')
        row+=" $rel |"
    done
    echo "$row"
    unset times med
done
