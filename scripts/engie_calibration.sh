#!/usr/bin/env sh
# The La Haute Borne calibration of docs/validation.md ("Wind-turbine gearbox"): calibrate
# models/mm82_wind_gearbox.toml on turbine R80711 (spring 2017: the first 14 days fitted, the
# rest held out), then predict R80711 in summer 2016 and R80721 in both periods with the
# calibrated model, and print the table of the docs.
#
#   sh scripts/engie_calibration.sh [EXTRACT_DIR] [OUT_DIR]
#
# EXTRACT_DIR holds the extract written by scripts/engie_extract.py (default
# validation/engie_la_haute_borne/data; see validation/engie_la_haute_borne/SOURCE.md).
set -eu
extract=${1:-validation/engie_la_haute_borne/data}
out=${2:-runs/engie_la_haute_borne}
if [ ! -f "$extract/R80711_2017-spring.csv" ]; then
    echo "no extract in $extract: build it with scripts/engie_extract.py (validation/engie_la_haute_borne/SOURCE.md)" >&2
    exit 1
fi
cargo build --release --quiet
bin=target/release/geartherm
mkdir -p "$out"
python3 scripts/engie_traces.py "$extract" "$out/traces"
"$bin" calibrate models/mm82_wind_gearbox.toml --trace "$out/traces/R80711_2017-spring.csv" \
    --fit 'losses.multiplier.sliding=0.05:50' \
    --fit 'losses.multiplier.churning=0.01:100' \
    --fit 'thermal.coolers["oil_cooler"].capacity_rate_w_per_k=100:30000' \
    --fit 'thermal.coolers["oil_cooler"].thermostat.open_c=45:61' \
    --fit 'thermal.links["gearbox-nacelle"].h_w_per_m2k=0.5:100' \
    --holdout 1209600:2400000 --max-iterations 60 --out "$out/fit_R80711"
for t in R80711_2016-summer R80721_2017-spring R80721_2016-summer; do
    "$bin" calibrate "$out/fit_R80711/calibrated.toml" --trace "$out/traces/$t.csv" \
        --holdout 0:1e9 --out "$out/predict_$t" >/dev/null
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
fit = json.load(open(f"{out}/fit_R80711/calibration.json"))
print("| parameter | start | fitted | 95 % interval |")
print("|---|---|---|---|")
for p in fit["parameters"]:
    print(f"| `{p['key_path']}` | {p['start']:g} | {p['value']:.4g} | [{p['ci95_low']:.4g}, {p['ci95_high']:.4g}] |")
print()
print("| turbine, period | rows | sump RMSE, K | max error, K | bias, K |")
print("|---|---|---|---|---|")
c = fit["channels"][0]
for label, e in [("R80711, spring 2017, days 1–14 (fitted)", c["fitted"]), ("R80711, spring 2017, days 15–27 (held out)", c["holdout"])]:
    print(f"| {label} | {e['rows']} | {e['rmse_k']:.2f} | {e['max_abs_k']:.2f} | {e['bias_k']:+.2f} |")
for t, label in [("R80711_2016-summer", "R80711, summer 2016 (predicted)"), ("R80721_2017-spring", "R80721, spring 2017 (predicted)"), ("R80721_2016-summer", "R80721, summer 2016 (predicted)")]:
    e = json.load(open(f"{out}/predict_{t}/calibration.json"))["channels"][0]["holdout"]
    print(f"| {label} | {e['rows']} | {e['rmse_k']:.2f} | {e['max_abs_k']:.2f} | {e['bias_k']:+.2f} |")
print()
print(f"fit: {fit['fit']['evaluations']} evaluations, stop: {fit['fit']['stop']}, σ = {fit['fit']['sigma_k']:.3f} K, {fit['fit']['wall_time_s']:.1f} s")
PY
