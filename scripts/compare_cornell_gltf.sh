#!/usr/bin/env bash
# The glTF Cornell box (scenes/cornell-box-gltf.gltf, written by
# scripts/make_gltf_scenes.py) against the XML one (scenes/cornell-box.xml)
# in trilux, both in RGB mode (the glTF file holds the XML's spectra as
# Mitsuba's RGB mode converts them): 128 x 128, 64 spp, default quality.
# Prints the difference of the two files' images and, as the noise it is
# judged against, the difference of two renders of the XML file with
# different seeds (both unmasked and with the reference's emitter mask).
# Usage: scripts/compare_cornell_gltf.sh [OUT_FOLDER] (default target/cornell-gltf)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/cornell-gltf}
mkdir -p "$out"
cargo build --quiet --release -p trilux -p xtask
bin=target/release
common=(--width 128 --height 128 --spp 64 --mode rgb)
"$bin/trilux" render scenes/cornell-box.xml "${common[@]}" --seed 0 -o "$out/xml-seed0.exr"
"$bin/trilux" render scenes/cornell-box.xml "${common[@]}" --seed 1 -o "$out/xml-seed1.exr"
"$bin/trilux" render scenes/cornell-box-gltf.gltf "${common[@]}" --seed 1 -o "$out/gltf-seed1.exr"
mask=tests/golden/cornell-box.mask.exr
echo "glTF (seed 1) against XML (seed 0):"
"$bin/xtask" golden compare "$out/gltf-seed1.exr" "$out/xml-seed0.exr" --mask "$mask"
echo "noise: XML (seed 1) against XML (seed 0):"
"$bin/xtask" golden compare "$out/xml-seed1.exr" "$out/xml-seed0.exr" --mask "$mask"
