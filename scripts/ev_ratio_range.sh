#!/bin/sh
# The EV reducer's overall ratio is not published: "160 km/h at a maximum of 16 000 rpm" bounds it
# from above (12.68 with the model's dynamic wheel radius 0.3364 m), VW's "10x" is a round figure.
# This prints the loss at 100 km/h on the level (road load of models/ev_reducer.toml's [vehicle]:
# F = m g c_r + ½ ρ c_d A v², ρ = 1.2 kg/m³) across 10.0–12.65, by the output gear's tooth count
# (stage 2 = 17/z4; stage 1 stays 19/61): `losses` at 60 and 80 °C oil and `steady` at its
# equilibrium (docs/validation.md "EV reducer: the ratio"). Run from the repository root after
# `cargo build --release`.
set -e
bin=./target/release/geartherm
F=$(python3 -c "print(1819*9.80665*0.0075 + 0.5*1.2*0.267*2.36*(100/3.6)**2)")
for z in 53 57 61 64 67; do
  set -- $(python3 -c "
import math
i = (61/19)*($z/17); r = 0.3364; v = 100/3.6
print(f'{i:.4f} {v/r*30/math.pi*i:.2f} {$F*r/i:.4f}')")
  i=$1; rpm=$2; tq=$3
  for t in 60 80; do
    $bin losses models/ev_reducer.toml --set "gears[3].teeth=$z" --gear D --speed-rpm "$rpm" \
      --torque-nm "$tq" --oil-temp-c "$t" --json 2>/dev/null | python3 -c "
import json, sys
v = json.load(sys.stdin)
parts = ', '.join(f'{k[5:-2]} {x:.1f}' for k, x in v.items() if k.startswith('loss_') and k != 'loss_total_w' and x)
print(f'z4 $z ratio $i {float(\"$rpm\"):.0f} rpm {float(\"$tq\"):.2f} N m oil $t C: total {v[\"loss_total_w\"]:.1f} W ({parts})')"
  done
  $bin steady models/ev_reducer.toml --set "gears[3].teeth=$z" --gear D --speed-rpm "$rpm" \
    --torque-nm "$tq" --vehicle-speed-kmh 100 --json 2>/dev/null | python3 -c "
import json, sys
v = json.load(sys.stdin)
print(f'z4 $z ratio $i steady: total {v[\"loss_total_w\"]:.1f} W, efficiency {v[\"efficiency\"]:.4f}')"
done
