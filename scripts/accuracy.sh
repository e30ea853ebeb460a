#!/usr/bin/env bash
# Regenerates the figures of docs/accuracy.md into assets/accuracy/:
# convergence studies of the shipped scenes and the table of effect costs.
# Usage: scripts/accuracy.sh [BUDGET_SECONDS]   (default 20 per configuration)
set -euo pipefail
cd "$(dirname "$0")/.."
budget=${1:-20}
cargo build --release --quiet
p=./target/release/prism
out=assets/accuracy
mkdir -p "$out"
# The path tracer's own studies name it: `Auto`, the default, takes BDPT on some of these.
path=(--set render.integrator.kind=Path)
$p converge scenes/cornell.ron --size 128x128 --reference-spp 4096 --budget "$budget" "${path[@]}" \
    --vary light_sampling=Nee,Path --vary max_depth=3,12 -o "$out/cornell" --quiet > /dev/null
$p converge scenes/caustics.ron --size 128x128 --reference-spp 4096 --budget "$budget" "${path[@]}" \
    --vary fresnel=Exact,Schlick -o "$out/caustics" --quiet > /dev/null
# Dispersive scenes: hero wavelength sampling (4 wavelengths per path) against one.
$p converge scenes/diamond_bunny.ron --size 96x72 --reference-spp 8192 --budget "$budget" "${path[@]}" \
    --vary wavelengths=1,4 -o "$out/diamond_bunny" --quiet > /dev/null
$p converge scenes/prism.ron --size 96x60 --reference-spp 16384 --budget "$budget" "${path[@]}" \
    --vary wavelengths=1,4 -o "$out/prism" --quiet > /dev/null
# What hero sampling buys where no interface disperses: the Cornell box under a dim D65 sky
# (a spectral emitter, so SPECTRAL is on and the reference is spectral too).
$p converge scenes/cornell.ron --size 96x96 --reference-spp 4096 --budget "$budget" "${path[@]}" \
    --set 'environment=Constant(Illuminant(spectrum: D65, scale: 0.05))' \
    --vary wavelengths=1,4 -o "$out/cornell_spectral" --quiet > /dev/null
# The path tracer against BDPT where lights reach specular surfaces (each reference by `Auto`).
estimators() {
    $p converge "scenes/$1.ron" --size "$2" --reference-spp "$3" --budget "$budget" \
        --vary integrator.kind=Path,Bdpt -o "$out/$1_estimators" --quiet > /dev/null
}
estimators caustics 128x128 4096
estimators prism 96x60 16384
estimators diamond_bunny 96x72 8192
# Effects absent (forced on to measure them) and present, one scene each at least.
$p costs scenes/cornell.ron scenes/caustics.ron scenes/motion_blur.ron scenes/earth_dof.ron \
    scenes/textures.ron scenes/god_rays.ron scenes/prism.ron \
    --size 128x128 --spp 8 --runs 5 > "$out/effect_costs.md"


echo "wrote $out"
python3 scripts/readme_figures.py
