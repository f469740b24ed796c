#!/bin/sh
# Regenerates the reference reports shown in the README (run from the repository root).
set -e
cargo build --release
./target/release/geartherm run models/at6_lepelletier.toml --cycle wltc --out plots/at6_wltc --report --quiet
./target/release/geartherm map models/fzg_c.toml --gear 1 --speed-rpm 300:3000:28 --torque-nm 0:300:31 --out plots/fzg_c_map --quiet
./target/release/geartherm validate validation --out plots/validation --doc docs/validation.md > /dev/null
./target/release/geartherm run models/ev_reducer.toml --cycle wltc --out plots/ev_reducer_wltc --report --quiet
./target/release/geartherm run models/ev_reducer.toml --cycle artemis_motorway130 --out plots/ev_reducer_motorway --report --quiet
./target/release/geartherm map models/ev_reducer.toml --gear D --speed-rpm 0:16000:33 --torque-nm 0:90:31 --out plots/ev_reducer_map --quiet
./target/release/geartherm rating models/ev_reducer.toml --gear D --speed-rpm 500:16000:32 --oil-limit-c 110 --torque-max-nm 310 --out plots/ev_reducer_rating --quiet > /dev/null
./target/release/geartherm rating models/fzg_c.toml --gear 1 --speed-rpm 250:6000:24 --oil-limit-c 100 --out plots/fzg_c_rating --quiet > /dev/null
rm -rf plots/at6_study
./target/release/geartherm study models/studies/at6_wltc_lhs.toml --out plots/at6_study --quiet > /dev/null
rm -f plots/at6_study/journal.jsonl plots/at6_study/study.parquet   # the table is study.csv
rm -rf plots/at6_uq plots/at6_uq_sobol
./target/release/geartherm uq models/studies/at6_wltc_uq.toml --limit sump=85 --out plots/at6_uq --report --quiet > /dev/null
./target/release/geartherm uq models/studies/at6_wltc_uq.toml --sobol --samples 128 --out plots/at6_uq_sobol --report --quiet > /dev/null
rm -f plots/at6_uq/journal.jsonl plots/at6_uq/*.parquet plots/at6_uq_sobol/journal.jsonl plots/at6_uq_sobol/*.parquet plots/at6_uq_sobol/bands.*
