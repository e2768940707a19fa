#!/usr/bin/env bash
# Regenerates the GENERATED demo R-Test set measurements/demo-vmc/pos-*/*.csv from the truth
# machine demo-vmc-true.toml beside this script: at two circle-centre positions (pos-a:
# X = 150, Y = −100, Z = 0 mm; pos-b: X = −150, Y = 100, Z = 0 mm, as each folder's rtest.toml
# states), 18 circle tests each (planes xy, yz, zx; cw and ccw; set accelerations 2, 5, 8 m/s²;
# r = 2 mm; 5 steady revolutions; 1 kHz), R-Test noise σ = 1.4 µm on the external coordinates.
# The noise is seeded: the files are reproducible bit for bit.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$(dirname "$here")"
cd "$here/../../.."
cargo build --release --quiet
seed=1
for pos in "pos-a 150,-100,0" "pos-b -150,100,0"; do
  set -- $pos
  for plane in xy yz zx; do
    for dir in cw ccw; do
      for acc in 2 5 8; do
        ./target/release/eij simulate circle --machine "$here/demo-vmc-true.toml" \
          --position-mm "$2" --plane "$plane" --radius-mm 2 --accel-m-s2 "$acc" --direction "$dir" \
          --revolutions 5 --rate-hz 1000 --noise-um 1.4 --seed "$seed" \
          --required-only --decimals 5 --out "$out/$1/${plane}_${dir}_${acc}.csv"
        seed=$((seed + 1))
      done
    done
  done
done
