#!/usr/bin/env bash
# Regenerates the GENERATED demo R-Test set measurements/demo-vmc/*.csv from the truth machine
# demo-vmc-true.toml beside this script: 24 circle tests (planes xy, yz, zx; cw and ccw;
# set accelerations 2, 4, 6, 8 m/s²; r = 2 mm; 5 steady revolutions; 1 kHz), circle centre
# at X = 150, Y = −100, Z = 0 mm (the R-Test nest off the table centre, as rtest.toml in that
# folder states), R-Test noise σ = 1.4 µm on the external coordinates (seeded: the files are
# reproducible bit for bit).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$(dirname "$here")"
cd "$here/../../.."
cargo build --release --quiet
seed=1
for plane in xy yz zx; do
  for dir in cw ccw; do
    for acc in 2 4 6 8; do
      ./target/release/eij simulate circle --machine "$here/demo-vmc-true.toml" \
        --plane "$plane" --radius-mm 2 --accel-m-s2 "$acc" --direction "$dir" \
        --position-mm 150,-100,0 --revolutions 5 --rate-hz 1000 --noise-um 1.4 --seed "$seed" \
        --required-only --decimals 5 --out "$out/${plane}_${dir}_${acc}.csv"
      seed=$((seed + 1))
    done
  done
done
