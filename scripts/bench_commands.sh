#!/usr/bin/env sh
# Whole-command timings of geartherm: median wall time of repeated runs, with
# hyperfine (Debian: `apt-get install -y hyperfine`). Usage, from the repository root after
# `cargo build --release`:
#   scripts/bench_commands.sh [RUNS]          (default 30 runs after 3 warm-ups)
# Prints one line per command: median, mean, min (ms) and the user + system CPU time, which is
# less disturbed than wall time on a shared machine. Figures go to docs/performance.md.
set -eu
RUNS="${1:-30}"
BIN="${GEARTHERM_BIN:-./target/release/geartherm}"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
command -v hyperfine >/dev/null || { echo "hyperfine not found (apt-get install -y hyperfine)" >&2; exit 1; }
i=0
while IFS= read -r cmd; do
    [ -z "$cmd" ] && continue
    i=$((i + 1))
    hyperfine -N --warmup 3 --runs "$RUNS" --export-json "$OUT/$i.json" "$BIN $cmd" >/dev/null 2>&1
    python3 - "$OUT/$i.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["results"][0]
ms = lambda s: 1e3 * s
print(f"{ms(r['median']):7.1f} ms median  {ms(r['mean']):7.1f} mean  {ms(r['min']):7.1f} min  "
      f"cpu {ms(r['user'] + r['system']):6.1f} ms   geartherm {r['command'].split(' ', 1)[1]}")
PY
done <<'CMDS'
losses models/at6_lepelletier.toml --gear 1 --speed-rpm 2000 --torque-nm 100 --oil-temp-c 80
run models/at6_lepelletier.toml --cycle wltc --summary-only
steady models/at6_lepelletier.toml --gear 3 --speed-rpm 2000 --torque-nm 150
losses models/fzg_c.toml --gear 1 --speed-rpm 2000 --torque-nm 100 --oil-temp-c 80
run models/fzg_c.toml --cycle wltc --summary-only
run models/helical_stage.toml --cycle wltc --summary-only
run models/pt6_spur_pair.toml --cycle wltc --summary-only
CMDS
