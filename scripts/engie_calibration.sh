#!/usr/bin/env sh
# The La Haute Borne calibration of docs/validation.md ("Wind-turbine gearbox"): calibrate
# validation/engie_la_haute_borne/mm82_sump_only.toml (the MM82 model with one oil node, no
# bearings) on turbine R80711 (spring 2017: the first 14 days fitted, the
# rest held out), then predict R80711 in summer 2016 and R80721 in both periods with the
# calibrated model and the band of its calibration (--band-from); once by least squares (with
# the profile likelihood of the churning level), once with priors on the loss levels; print the
# tables of the docs.
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
fit() {
    dir=$1; shift
    "$bin" calibrate validation/engie_la_haute_borne/mm82_sump_only.toml --trace "$out/traces/R80711_2017-spring.csv" \
        --fit 'losses.multiplier.sliding=0.05:50' \
        --fit 'losses.multiplier.churning=0.01:100' \
        --fit 'thermal.coolers["oil_cooler"].capacity_rate_w_per_k=100:30000' \
        --fit 'thermal.coolers["oil_cooler"].thermostat.open_c=45:61' \
        --fit 'thermal.links["gearbox-nacelle"].h_w_per_m2k=0.5:100' \
        --holdout 1209600:2400000 --max-iterations 60 \
        --gearbox-kind wind-turbine --rated=1680:-11600 --out "$dir" "$@" >/dev/null
    for t in R80711_2016-summer R80721_2017-spring R80721_2016-summer; do
        "$bin" calibrate "$dir/calibrated.toml" --trace "$out/traces/$t.csv" \
            --holdout 0:1e9 --band-from "$dir/calibration.json" --out "$dir/predict_$t" >/dev/null
    done
}
# Least squares (residual model ar1), with the profile likelihood of the churning level.
fit "$out/fit_R80711" --profile 'losses.multiplier.churning'
# The same with log-normal priors on the two loss levels (median 1: the loss laws as they stand).
fit "$out/fit_R80711_prior" --prior 'losses.multiplier.sliding=lognormal:1:0.7' \
    --prior 'losses.multiplier.churning=lognormal:1:0.7'
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
for name, title in (("fit_R80711", "least squares"), ("fit_R80711_prior", "with log-normal priors (median 1, sd_ln 0.7) on both loss multipliers")):
    d = f"{out}/{name}"
    fit = json.load(open(f"{d}/calibration.json"))
    print(f"## {title}\n")
    print("| parameter | start | fitted | 95 % interval, AR(1) errors | 95 % interval, independent errors | prior: posterior/prior width, prior's share |")
    print("|---|---|---|---|---|---|")
    for p in fit["parameters"]:
        q = p.get("prior")
        pr = f"{q['width_ratio']:.2f}, {100 * q['prior_share']:.0f} %" if q else "—"
        print(f"| `{p['key_path']}` | {p['start']:g} | {p['value']:.4g} | [{p['ci95_low']:.4g}, {p['ci95_high']:.4g}] | [{p['ci95_independent_low']:.4g}, {p['ci95_independent_high']:.4g}] | {pr} |")
    print()
    print("| turbine, period | rows | sump RMSE, K | max error, K | bias, K | inside the 95 % band |")
    print("|---|---|---|---|---|---|")
    c = fit["channels"][0]
    rows = [("R80711, spring 2017, days 1–14 (fitted)", c["fitted"]), ("R80711, spring 2017, days 15–27 (held out)", c["holdout"])]
    for t, label in [("R80711_2016-summer", "R80711, summer 2016 (predicted)"), ("R80721_2017-spring", "R80721, spring 2017 (predicted)"), ("R80721_2016-summer", "R80721, summer 2016 (predicted)")]:
        rows.append((label, json.load(open(f"{d}/predict_{t}/calibration.json"))["channels"][0]["holdout"]))
    for label, e in rows:
        print(f"| {label} | {e['rows']} | {e['rmse_k']:.2f} | {e['max_abs_k']:.2f} | {e['bias_k']:+.2f} | {100 * e['inside_band95']:.1f} % |")
    print()
    n = c["noise"]
    print(f"sump residuals (fitted days): φ = {n['phi']:.3f}, σ_a = {n['innovation_sd_k']:.3f} K, acf lags 1/2/6 = " + " / ".join(f"{a:.3f}" for a in n["autocorrelation_lag_1_2_6"]) + f"; t at ν = {fit['fit']['dof']}")
    pl = fit["plausibility"]
    for key, label in (("highest_power", f"highest-power rows ({pl['rows']})"), ("rated", "rated point")):
        x = pl[key]
        by = ", ".join(f"{s} {v / 1e3:.1f}" for s, v in x["loss_by_source_w"])
        print(f"{label}: {x['power_w'] / 1e3:.0f} kW, oil {x['oil_temp_c']:.1f} °C: loss {x['loss_total_w'] / 1e3:.1f} kW ({by} kW), efficiency {x['efficiency']:.4f}")
    r = pl["reference"]
    print(f"sourced figure ({r['kind']}): {r['statement']}; the model {100 * r['loss_share']:.1f} % ({'within' if r['inside'] else 'outside'} {100 * r['loss_share_bounds'][0]:.1f}–{100 * r['loss_share_bounds'][1]:.1f} %)")
    for dd in fit["identifiability"]:
        if dd["status"] != "determined":
            comps = ", ".join(f"{x['component']:+.3f} ln {x['key_path']}" for x in dd["components"])
            print(f"{dd['status']}: ({comps}), relative eigenvalue {dd['relative_eigenvalue']:.1e}, 95 % step ±{dd['ci95_half_width']:.3f}")
    for pr in fit.get("profiles", []):
        lo = "beyond the grid" if pr["ci95_low"] is None else f"{pr['ci95_low']:.4g}"
        hi = "beyond the grid" if pr["ci95_high"] is None else f"{pr['ci95_high']:.4g}"
        pts = ", ".join(f"{x['value']:.3g}: {x['statistic']:.2f}" for x in pr["points"])
        print(f"profile of `{pr['key_path']}`: 95 % interval [{lo}, {hi}] (D ≤ {pr['threshold']:.2f}); D along the grid: {pts}")
    print(f"fit: {fit['fit']['evaluations']} evaluations, stop: {fit['fit']['stop']}, σ = {fit['fit']['sigma_k']:.3f} K, {fit['fit']['wall_time_s']:.1f} s\n")
PY
