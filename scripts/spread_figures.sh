#!/bin/sh
# Figures of docs/validation.md, "Model-form spread": the MM82 wheel's churning models, the FZG C
# pair's friction laws and the SKF drag editions of the bundled bearings, from `losses --json`.
# Usage: scripts/spread_figures.sh [path to geartherm] (default target/release/geartherm).
set -e
B=${1:-target/release/geartherm}
row() { # model gear rpm Nm °C source
  "$B" losses "$1" --gear "$2" --speed-rpm "$3" --torque-nm "$4" --oil-temp-c "$5" --json 2>/dev/null |
    python3 -c "
import json, sys
d = json.load(sys.stdin)
for it in d['spread']['items']:
    if it['source'] != '$6' or len(it['models']) < 2:
        continue
    vals = ', '.join('%s%s %s' % (m['label'], '*' if m['default'] else '',
                                 'n/a' if m['w'] is None else '%.1f W' % m['w']) for m in it['models'])
    f = it['factor']
    print('| $1 | $3 rpm, $4 N m, $5 °C | %s | %s | %s |' % (it['name'], vals, '%.1f' % f if f else 'inf'))
"
}
echo "| model | point | item | values (* default) | max/min |"
echo "|---|---|---|---|---:|"
for t in 40 50 60; do row models/mm82_wind_gearbox.toml run 1680 5000 $t churning; done
for p in "1500 100 60" "1500 300 90" "3000 300 90"; do set -- $p; row models/fzg_c.toml 1 $1 $2 $3 sliding; done
for t in 40 90; do row models/fzg_c.toml 1 3000 100 $t bearing; done
row models/ev_reducer.toml D 8000 100 60 bearing
