#!/usr/bin/env bash
# Regenerates the GENERATED R-Test set measurements/demo-vmc-flex/pos-*/*.csv from the truth
# machine demo-vmc-flex-true.toml beside this script (machines/demo-vmc-flex.toml with guideway
# reduction factors and the column's stiffness factor 0.7): at three circle-centre positions
# (pos-a: X = 150, Y = −100, Z = 0 mm; pos-b: X = −150, Y = 100, Z = 250 mm; pos-c, the hold-out
# set for `eij identify --validate`: X = 0, Y = 50, Z = 120 mm; as each folder's rtest.toml
# states), 18 circle tests each (planes xy, yz, zx; cw and ccw; set accelerations 2, 5, 8 m/s²;
# r = 2 mm; 5 steady revolutions; 1 kHz), R-Test noise σ = 1.4 µm on the external coordinates.
# The noise is seeded (seeds 1001 …): the files are reproducible bit for bit.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$(dirname "$here")"
cd "$here/../../.."
cargo build --release --quiet
seed=1001
for pos in "pos-a 150,-100,0" "pos-b -150,100,250" "pos-c 0,50,120"; do
  set -- $pos
  mkdir -p "$out/$1"
  IFS=, read -r x y z <<< "$2"
  printf '# Conditions of the circle tests in this folder (read by `eij identify`).\nradius_mm = 2.0\nposition_mm = [%.1f, %.1f, %.1f]\n' \
    "$x" "$y" "$z" > "$out/$1/rtest.toml"
  for plane in xy yz zx; do
    for dir in cw ccw; do
      for acc in 2 5 8; do
        ./target/release/eij simulate circle --machine "$here/demo-vmc-flex-true.toml" \
          --position-mm "$2" --plane "$plane" --radius-mm 2 --accel-m-s2 "$acc" --direction "$dir" \
          --revolutions 5 --rate-hz 1000 --noise-um 1.4 --seed "$seed" \
          --required-only --decimals 5 --out "$out/$1/${plane}_${dir}_${acc}.csv"
        seed=$((seed + 1))
      done
    done
  done
done
