#!/usr/bin/env python3
"""The MM82 model with its bearings and measured nodes, fitted to several channels of the La Haute
Borne trace at once (docs/validation.md, "Wind-turbine gearbox: four channels, bearings").

    python3 scripts/engie_channels.py [--data DIR] [--out DIR]

DIR (default ../shared/data/engie_la_haute_borne) holds the four period files
R80711_2017-spring.csv, R80711_2016-summer.csv, R80721_2017-spring.csv, R80721_2016-summer.csv.
Three calibrations on R80711 spring 2017 (days 1–14 fitted, days 15–27 held out), each followed
by predictions of R80711 summer 2016 and R80721 in both periods with its band (--band-from):

  A  validation/engie_la_haute_borne/mm82_sump_only.toml (one oil node, no bearings) on the
     sump channel, the five parameters of scripts/engie_calibration.sh (before);
  B  models/mm82_wind_gearbox.toml (bearings, inlet and bearing nodes) on the sump channel
     alone, the same five parameters;
  C  models/mm82_wind_gearbox.toml on four channels (sump, inlet, two bearings), the five and
     the circulation's conductance, the inlet line's h and the two bearings' conductances to
     the oil (after).
B and C start from A's fitted values of the five (--set). A calibration that fails is printed
as such and the others go on.

Prints the tables of docs/validation.md and writes OUT/figures.json.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

PERIODS = ["R80711_2017-spring", "R80711_2016-summer", "R80721_2017-spring", "R80721_2016-summer"]
SUMP_ONLY = "validation/engie_la_haute_borne/mm82_sump_only.toml"
MODEL = "models/mm82_wind_gearbox.toml"
FIVE = [
    "losses.multiplier.sliding=0.05:50",
    "losses.multiplier.churning=0.01:100",
    'thermal.coolers["oil_cooler"].capacity_rate_w_per_k=100:30000',
    'thermal.coolers["oil_cooler"].thermostat.open_c=45:61',
    'thermal.links["gearbox-nacelle"].h_w_per_m2k=0.5:100',
]
CHANNEL_KEYS = [
    'thermal.links["circulation"].conductance_w_per_k=100:100000',
    'thermal.links["inlet-nacelle"].h_w_per_m2k=0.1:1000',
    'thermal.links["hss_bearing_1-oil"].conductance_w_per_k=5:20000',
    'thermal.links["hss_bearing_2-oil"].conductance_w_per_k=5:20000',
]
CASES = [
    ("A", SUMP_ONLY, "sump", FIVE, "one oil node, no bearings; sump"),
    ("B", MODEL, "sump", FIVE, "bearings and measured nodes; sump alone"),
    ("C", MODEL, "four", FIVE + CHANNEL_KEYS, "bearings and measured nodes; four channels"),
]
FIT_OPTIONS = ["--holdout", "1209600:2400000", "--max-iterations", "60",
               "--gearbox-kind", "wind-turbine", "--rated=1680:-11600"]
ROWS = [
    ("R80711, spring 2017, days 1–14 (fitted)", "fit", "fitted"),
    ("R80711, spring 2017, days 15–27 (held out)", "fit", "holdout"),
    ("R80711, summer 2016 (predicted)", "R80711_2016-summer", "holdout"),
    ("R80721, spring 2017 (predicted)", "R80721_2017-spring", "holdout"),
    ("R80721, summer 2016 (predicted)", "R80721_2016-summer", "holdout"),
]


def run(args):
    r = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)}: exit {r.returncode}\n{r.stderr}")


def traces(data, out):
    """The sump-only and the four-channel traces of the four periods."""
    src = tempfile.mkdtemp(prefix="engie_periods_")
    for p in PERIODS:
        os.symlink(os.path.abspath(os.path.join(data, p + ".csv")), os.path.join(src, p + ".csv"))
    run([sys.executable, "scripts/engie_traces.py", src, os.path.join(out, "sump")])
    run([sys.executable, "scripts/engie_traces.py", "--channels", src, os.path.join(out, "four")])


def case(bin_, out, name, model, kind, keys, start=None):
    """Calibrate `model` on the `kind` traces, fitting `keys` (from the values of the fit
    `start` where it has them), and predict the other periods."""
    d = os.path.join(out, name)
    t = lambda p: os.path.join(out, kind, p + ".csv")
    args = [bin_, "calibrate", model, "--trace", t(PERIODS[0]), "--out", d] + FIT_OPTIONS
    for k in keys:
        args += ["--fit", k]
    for p in (start or {}).get("parameters", []):
        args += ["--set", f"{p['key_path']}={p['value']!r}"]
    run(args)
    fit = json.load(open(os.path.join(d, "calibration.json")))
    predicted = {}
    for p in PERIODS[1:]:
        pd = os.path.join(d, "predict_" + p)
        run([bin_, "calibrate", os.path.join(d, "calibrated.toml"), "--trace", t(p), "--holdout", "0:1e9",
             "--band-from", os.path.join(d, "calibration.json"), "--out", pd])
        predicted[p] = json.load(open(os.path.join(pd, "calibration.json")))
    return fit, predicted


def errors(fit, predicted):
    """Per channel (column), the errors of each row of ROWS."""
    out = {}
    for c, ch in enumerate(fit["channels"]):
        rows = []
        for label, src, part in ROWS:
            e = ch[part] if src == "fit" else predicted[src]["channels"][c][part]
            rows.append((label, e))
        out[ch["column"]] = rows
    return out


def report(name, title, fit, predicted):
    print(f"#### {name}: {title}\n")
    print("| parameter | fitted | 95 % interval (AR(1) errors) |")
    print("|---|---|---|")
    for p in fit["parameters"]:
        lo, hi = p["ci95_low"], p["ci95_high"]
        ci = f"[{lo:.4g}, {hi:.4g}]" if lo is not None else "—"
        print(f"| `{p['key_path']}` | {p['value']:.4g} | {ci} |")
    print()
    print("| channel | turbine, period | rows | RMSE, K | bias, K | inside the 95 % band |")
    print("|---|---|---|---|---|---|")
    for col, rows in errors(fit, predicted).items():
        for label, e in rows:
            print(f"| {col} | {label} | {e['rows']} | {e['rmse_k']:.2f} | {e['bias_k']:+.2f} | {100 * e['inside_band95']:.1f} % |")
    print()
    for ch in fit["channels"]:
        n = ch["noise"]
        print(f"{ch['column']} residuals (fitted days): φ = {n['phi']:.3f}, σ_a = {n['innovation_sd_k']:.3f} K, "
              f"stationary σ {n['marginal_sd_k']:.3f} K")
    pl = fit["plausibility"]
    for key, label in (("highest_power", f"highest-power rows ({pl['rows']})"), ("rated", "rated point")):
        x = pl[key]
        by = ", ".join(f"{s} {v / 1e3:.1f}" for s, v in x["loss_by_source_w"])
        print(f"{label}: {x['power_w'] / 1e3:.0f} kW, oil {x['oil_temp_c']:.1f} °C: loss {x['loss_total_w'] / 1e3:.1f} kW "
              f"({by} kW), efficiency {x['efficiency']:.4f}")
    for dd in fit["identifiability"]:
        if dd["status"] != "determined":
            comps = ", ".join(f"{x['component']:+.3f} ln {x['key_path']}" for x in dd["components"])
            hw = dd["ci95_half_width"]
            hw = "none" if hw is None else f"±{hw:.3f}"
            print(f"{dd['status']}: ({comps}), relative eigenvalue {dd['relative_eigenvalue']:.1e}, 95 % step {hw}")
    f = fit["fit"]
    print(f"fit: {f['evaluations']} evaluations, stop: {f['stop']}, t at ν = {f['dof']}, {f['wall_time_s']:.1f} s")
    for w in fit["warnings"]:
        if "correlation" in w or "move together" in w or "not identifiable" in w or "bound" in w:
            print(f"warning: {w}")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default="../shared/data/engie_la_haute_borne")
    ap.add_argument("--out", default="runs/engie_channels")
    a = ap.parse_args()
    run(["cargo", "build", "--release", "--quiet", "-p", "geartherm"])
    bin_ = "target/release/geartherm"
    os.makedirs(a.out, exist_ok=True)
    traces(a.data, a.out)
    figures = {}
    first = None
    for name, model, kind, keys, title in CASES:
        try:
            fit, predicted = case(bin_, a.out, name, model, kind, keys, first)
        except SystemExit as e:
            print(f"#### {name}: {title}\n\nno result: {e}\n")
            continue
        first = first or fit
        report(name, title, fit, predicted)
        figures[name] = {
            "parameters": {p["key_path"]: p["value"] for p in fit["parameters"]},
            "errors": {c: [(l, e["rmse_k"], e["inside_band95"]) for l, e in rows]
                       for c, rows in errors(fit, predicted).items()},
            "efficiency": {k: fit["plausibility"][k]["efficiency"] for k in ("highest_power", "rated")},
            "identifiability": fit["identifiability"],
        }
    with open(os.path.join(a.out, "figures.json"), "w") as fh:
        json.dump(figures, fh, indent=1)


if __name__ == "__main__":
    main()
