#!/bin/sh
# Regenerates the reference reports shown in the README (run from the repository root).
set -e
cargo build --release
./target/release/geartherm run models/at6_lepelletier.toml --cycle wltc --out plots/at6_wltc --report --quiet
./target/release/geartherm map models/fzg_c.toml --gear 1 --speed-rpm 300:3000:28 --torque-nm 0:300:31 --out plots/fzg_c_map --quiet
./target/release/geartherm validate validation --out plots/validation --doc docs/validation.md > /dev/null
