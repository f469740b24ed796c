#!/usr/bin/env python3
"""Both La Haute Borne turbines in one calibration (docs/validation.md, "Wind-turbine gearbox:
both turbines in one fit"): the single-node MM82 model
(validation/engie_la_haute_borne/mm82_sump_only.toml) fitted to R80711's AND R80721's spring
2017 days 1–14 together, one gearbox type (loss levels and the housing's link to the nacelle
shared) with a cooler per turbine, both turbines' days 15–27 held out, both turbines' summer
2016 predicted by each turbine's calibrated model with the band of the fit; beside it the
single-turbine fit (R80711 days 1–14) predicting the same rows; each with the model file's
churning law (Changenet–Velex) and with Seetharaman and Kahraman's.

    python3 scripts/engie_turbines.py [--data DIR] [--out DIR] [--bin PATH] [--only NAME]
                                      [--residuals] [--variants] [--train-summer YEAR]

DIR holds the four period files R807*_2017-spring.csv, R807*_2016-summer.csv (default
../shared/data/engie_la_haute_borne; OUT default /tmp/geartherm_turbines). Prints one table
row per fit and held-out trace (sump RMSE, bias, fraction of the rows inside the 95 % band of
the fit's residual process and, for a fit of both turbines, of each turbine's own), the fitted
values, the least determined direction, the loss at the rated point and the run times, then
the table of docs/validation.md; writes OUT/figures.json. --residuals adds, per two-turbine
fit, where the residuals on each turbine's fitted days come from (slow and fast parts, by
measured sump, power and outdoor air); --variants runs the variants tried
(docs/validation.md's list) instead and prints their table (OUT/figures_variants.json).
Nothing is tuned on the held-out rows: each fit sees days 1–14 only (--holdout
1209600:2400000 in each trace's own time).

--train-summer YEAR adds to each fit, per turbine, the first 14 complete days (144 rows, every
cell filled, days of the record's local date) from 1 July of YEAR in the multi-year record
DIR/R807*_2013-2020.csv, chosen by data availability only. The CLI shares a per-trace parameter
by one trace or by all, not by a subset, so the summer days are appended to the turbine's
spring trace (the same trace name, R807*_2017-spring; the gap in time starts a new segment
from the measured temperatures): the turbine's cooler is then one value for its spring and
summer days. They lie after the held-out window (s 2 400 000 on), so days 15–27 stay held out
and summer 2016 unseen; the fitted rows are reported per window.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

MODEL = "validation/engie_la_haute_borne/mm82_sump_only.toml"
PERIODS = ["R80711_2017-spring", "R80711_2016-summer", "R80721_2017-spring", "R80721_2016-summer"]
HOLDOUT = "1209600:2400000"  # days 15–27 of a spring trace (s from its first row)
HELD = (1209600.0, 2400000.0)
CAP = 'thermal.coolers["oil_cooler"].capacity_rate_w_per_k'
OPEN = 'thermal.coolers["oil_cooler"].thermostat.open_c'
SHARED = [
    "losses.multiplier.sliding=0.05:50",
    "losses.multiplier.churning=0.01:100",
    'thermal.links["gearbox-nacelle"].h_w_per_m2k=0.5:100',
]
# The churning law of the model file is Changenet–Velex; `SEETHARAMAN` sets Seetharaman and
# Kahraman's instead (docs/validation.md, "both turbines in one fit": the Changenet–Velex
# regime bridge of wheel 1 lies inside the traces' speed and oil-temperature range).
SEETHARAMAN = ['losses.churning="seetharaman"']


def spec(fit, turbines, sets=(), model=MODEL, kind="sump"):
    """One calibration: its --fit and --set arguments, the turbines whose spring days 1–14 it fits,
    the model file (or a function of the output directory that writes one) and the traces
    (`sump`: engie_traces.py's; `sensor`: those with the sump column measured on a sensor node;
    `four`: engie_traces.py --channels)."""
    return {"fit": list(fit), "turbines": turbines, "sets": list(sets), "model": model, "kind": kind}


BOTH = ["R80711", "R80721"]
# The single-turbine fit is that of scripts/engie_calibration.sh (same parameters, same bounds).
FITS = {
    "single R80711": spec(SHARED + [f"{CAP}=100:30000", f"{OPEN}=45:61"], ["R80711"]),
    "both, cooler per turbine": spec(SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:61"], BOTH),
    "both, cooler and thermostat per turbine": spec(SHARED + [f"{CAP}@*=100:30000", f"{OPEN}@*=45:61"], BOTH),
    "single R80711, Seetharaman–Kahraman churning": spec(SHARED + [f"{CAP}=100:30000", f"{OPEN}=45:61"],
                                                         ["R80711"], SEETHARAMAN),
    "both, cooler per turbine, Seetharaman–Kahraman churning": spec(
        SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:61"], BOTH, SEETHARAMAN),
}

# The variants tried on the way (`--variants`; docs/validation.md lists their figures). Each is
# fitted on both turbines' days 1–14 with a cooler per turbine; the model changes are
# assumptions of the variant, not of the model file.
FULL = 'thermal.coolers["oil_cooler"].thermostat.full_c'
MASS = 'thermal.nodes["gearbox"].mass_kg=1000:60000'
NACELLE_AIR = ['thermal.coolers["oil_cooler"].cold="nacelle"']
# The cooler's fan at a fixed speed: its air stream's capacity rate (the fitted one, stated at
# 15 °C) follows the air's density, T_ref/T_air (docs/physics.md, "Fixed-speed fan cooler").
AIR_DENSITY = ['thermal.coolers["oil_cooler"].air_density_reference_c=15.0']
# The S–K refinements start from 30 (written as a float: a two-trace fit given an integer
# literal, `--set losses.multiplier.churning=30`, refuses the key as influencing no trace).
SK30 = SEETHARAMAN + ["losses.multiplier.churning=30.0"]
CHANNEL_KEYS = [
    'thermal.links["circulation"].conductance_w_per_k=100:100000',
    'thermal.links["inlet-nacelle"].h_w_per_m2k=0.1:1000',
    'thermal.links["hss_bearing_1-oil"].conductance_w_per_k=5:20000',
    'thermal.links["hss_bearing_2-oil"].conductance_w_per_k=5:20000',
]
# Churning heat into the body node instead of the oil.
HEAT_TO_BODY = '\n[[thermal.heat]]\nsource = "churning"\nto = { gearbox = 1.0 }\n'
# A sensor lag: the measured sump temperature is that of a 5 kg sensor (steel) joined to the oil
# by a fitted conductance (time constant m·c/G).
SENSOR = """
[[thermal.nodes]]
name = "sump_sensor"
mass_kg = 5.0
cp_j_per_kgk = 480.0

[[thermal.links]]
name = "sensor"
between = ["sump", "sump_sensor"]
conductance_w_per_k = 5.0
"""


def appended(text, file_name):
    """A model writer (spec's `model`): MODEL with `text` appended, written beside the fit's
    directory `d` (`calibrate` writes only into a directory of its own outputs)."""
    def write(d):
        path = f"{d}_{file_name}"
        with open(MODEL) as fh:
            base = fh.read()
        with open(path, "w") as fh:
            fh.write(base + text)
        return path
    return write


def four_starts(sliding, churning, cap, open_c):
    """The four-channel model's start (--set, floats: see SK30) near the single-node fit's values."""
    return [f"losses.multiplier.sliding={float(sliding)}", f"losses.multiplier.churning={float(churning)}",
            'thermal.links["gearbox-nacelle"].h_w_per_m2k=5.4', f"{CAP}={float(cap)}", f"{OPEN}={float(open_c)}"]


def variants():
    """The variants of `--variants`, as they were run (the bounds of each)."""
    wide = SHARED + [f"{CAP}@*=100:1e6", f"{OPEN}=45:61"]
    base = SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:61"]
    full = SHARED + [f"{CAP}@*=100:1e6", f"{OPEN}=45:57", f"{FULL}=57.5:75"]
    return {
        "cooler bound 1e6 W/K": spec(wide, BOTH),
        "cooler's air side on the nacelle": spec(wide, BOTH, NACELLE_AIR),
        "full_c fitted": spec(full, BOTH),
        "nacelle air side, full_c fitted": spec(full, BOTH, NACELLE_AIR),
        "nacelle air side, oil-gearbox h fitted": spec(
            wide + ['thermal.links["oil-gearbox"].h_w_per_m2k=1:2000'], BOTH, NACELLE_AIR),
        "gearbox mass fitted": spec(wide + [MASS], BOTH),
        "gearbox mass and full_c fitted": spec(full + [MASS], BOTH),
        "churning heat into the gearbox body": spec(wide, BOTH, model=appended(HEAT_TO_BODY, "churning_to_body.toml")),
        "sensor lag": spec(wide + ['thermal.links["sensor"].conductance_w_per_k=0.2:1000'], BOTH,
                           model=appended(SENSOR, "sump_sensor.toml"), kind="sensor"),
        "heater capacity per turbine": spec(wide + ['thermal.coolers["oil_heater"].capacity_rate_w_per_k@*=1:1e5'],
                                            BOTH),
        "heater set point per turbine": spec(wide + ['thermal.boundaries["heater"].temp_c@*=20:50'], BOTH),
        "four channels": spec(wide + CHANNEL_KEYS, BOTH, four_starts(1.74, 8.6, 13500, 56.2),
                              model="models/mm82_wind_gearbox.toml", kind="four"),
        "churning off": spec([SHARED[0], SHARED[2], f"{CAP}@*=100:1e6", f"{OPEN}=45:61"], BOTH,
                             ['losses.churning="off"']),
        "Stavytskyi churning": spec(wide, BOTH, ['losses.churning="stavytskyi"']),
        "S–K, cooler bound 1e6 W/K": spec(wide, BOTH, SK30),
        "S–K, nacelle air side": spec(wide, BOTH, SK30 + NACELLE_AIR),
        "S–K, gearbox mass fitted": spec(base + [MASS], BOTH, SK30),
        "S–K, heater capacity per turbine": spec(
            base + ['thermal.coolers["oil_heater"].capacity_rate_w_per_k@*=1:1e5'], BOTH, SK30),
        "S–K, thermostat per turbine": spec(SHARED + [f"{CAP}@*=100:30000", f"{OPEN}@*=45:61"], BOTH, SK30),
        "S–K, full_c fitted (58.5–75)": spec(SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:58", f"{FULL}=58.5:75"],
                                            BOTH, SK30),
        "S–K, full_c fitted (58.6–75)": spec(SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:58.5", f"{FULL}=58.6:75"],
                                            BOTH, SK30),
        "S–K, cooler air density (fixed-speed fan)": spec(
            SHARED + [f"{CAP}@*=100:30000", f"{OPEN}=45:61"], BOTH, SEETHARAMAN + AIR_DENSITY),
        "S–K, four channels": spec(base + CHANNEL_KEYS, BOTH, SEETHARAMAN + four_starts(0.55, 85, 5000, 57.2),
                                   model="models/mm82_wind_gearbox.toml", kind="four"),
    }


def complete_days(record, year, n=14):
    """The record's rows of the first `n` complete days (144 rows, no empty cell; the record's
    local date) from 1 July of `year`."""
    with open(record) as fh:
        rows = [x for x in csv.DictReader(fh) if x["Date_time"][:10] >= f"{year}-07-01"]
    by_day = {}
    for x in rows:
        by_day.setdefault(x["Date_time"][:10], []).append(x)
    days = [d for d in sorted(by_day) if len(by_day[d]) == 144 and
            all((v or "").strip() for x in by_day[d] for v in x.values())][:n]
    if len(days) < n:
        sys.exit(f"{record}: only {len(days)} complete days from {year}-07-01")
    return days, [x for d in days for x in by_day[d]]


def with_summer(data, src, year):
    """Each turbine's spring extract with its `year` summer days appended (complete_days), written
    into `src` (the name of the spring extract); prints the days taken."""
    for t in BOTH:
        with open(os.path.join(data, f"{t}_2017-spring.csv")) as fh:
            lines = fh.read().splitlines()
        head = [i for i, line in enumerate(lines) if line.startswith("Date_time")][0]
        days, rows = complete_days(os.path.join(data, f"{t}_2013-2020.csv"), year)
        cols = lines[head].split(",")
        mean = sum(float(x["Ot_avg"]) for x in rows) / len(rows)
        print(f"{t}: {year} summer days {', '.join(d[5:] for d in days)} ({len(rows)} rows, mean outdoor air "
              f"{mean:.1f} °C)")
        dest = os.path.join(src, f"{t}_2017-spring.csv")
        if os.path.lexists(dest):
            os.remove(dest)  # a link to the period file, or an earlier run's
        with open(dest, "w") as fh:
            fh.write(f"# {t}: 2017-spring extract, then the first 14 complete days from {year}-07-01 of "
                     f"{t}_2013-2020.csv\n")
            fh.write("\n".join(lines[head:]) + "\n")
            for x in rows:
                fh.write(",".join(x[c] for c in cols) + "\n")


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")


def traces(data, out, kinds, summer=None):
    """The directories of the traces of each kind in `kinds` (spec's `kind`), built under `out`
    (with `summer`, a year: the spring traces with that summer's days appended, with_summer)."""
    src = os.path.join(out, "records")
    os.makedirs(src, exist_ok=True)
    if summer:
        with_summer(data, src, summer)
    for p in PERIODS:
        link = os.path.join(src, p + ".csv")
        if os.path.exists(link) and not os.path.islink(link) and not summer:
            os.remove(link)  # an earlier --train-summer run's extract
        if not os.path.lexists(link) and not (summer and p.endswith("2017-spring")):
            os.symlink(os.path.abspath(os.path.join(data, p + ".csv")), link)
    dirs = {"sump": os.path.join(out, "traces"), "four": os.path.join(out, "traces_four"),
            "sensor": os.path.join(out, "traces_sensor")}
    subprocess.run([sys.executable, "scripts/engie_traces.py", src, dirs["sump"]], check=True, stdout=subprocess.DEVNULL)
    if "four" in kinds:
        subprocess.run([sys.executable, "scripts/engie_traces.py", "--channels", src, dirs["four"]], check=True,
                       stdout=subprocess.DEVNULL)
    if "sensor" in kinds:
        os.makedirs(dirs["sensor"], exist_ok=True)
        for p in PERIODS:
            with open(os.path.join(dirs["sump"], p + ".csv")) as fh:
                text = fh.read()
            head, rest = text.split("\n", 1)
            with open(os.path.join(dirs["sensor"], p + ".csv"), "w") as fh:
                fh.write(head.replace("node:sump", "node:sump_sensor") + "\n" + rest)
    return dirs


def own_ar1(fit_csv, trace_name, node="sump"):
    """The AR(1) residual process of one trace's fitted sump rows (fit.csv), estimated as
    `geartherm calibrate` estimates the fit's (src/job/calibrate/residuals.rs): φ by least squares
    on consecutive fitted rows of a segment with the bias −(1 + 3φ)/n added back, σ_a from the
    Prais–Winsten innovations."""
    x, cont = [], []
    prev = None
    with open(fit_csv) as fh:
        for row in csv.DictReader(fh):
            if row["trace"] != trace_name or row["holdout"] != "0":
                prev = None
                continue
            cont.append(prev is not None and prev == row["segment"])
            x.append(float(row[f"{node}_residual_k"]))
            prev = row["segment"]
    n = len(x)
    pairs = [i for i in range(1, n) if cont[i]]
    ls = sum(x[i] * x[i - 1] for i in pairs) / sum(x[i - 1] ** 2 for i in pairs)
    phi = max(-0.99, min(0.99, ls + (1.0 + 3.0 * ls) / n))
    ss = sum((x[i] - phi * x[i - 1]) ** 2 if cont[i] else (1.0 - phi * phi) * x[i] ** 2 for i in range(n))
    sigma = math.sqrt(ss / n)
    return {"phi": phi, "innovation_sd_k": sigma, "marginal_sd_k": sigma / math.sqrt(1.0 - phi * phi)}


def band_json(cal, turbine, trace_name, path, own_noise=None):
    """The fit's calibration.json restricted to the parameters `turbine`'s model holds: the shared
    ones and its own (`KEY@trace_name` written as KEY), their covariance the sub-block of the
    fit's (the marginal covariance of those coordinates), the band multiplier that of the trace
    `trace_name` (the fit's per-trace one); the residual process that of the fit (every trace's
    fitted rows together) or `own_noise` (φ, σ_a) in its place, then with Student's t as the
    multiplier (the Gaussian band of the turbine's own process)."""
    keep, params = [], []
    for k, p in enumerate(cal["parameters"]):
        key = p["key_path"]
        if "@" in key.rsplit("]", 1)[-1]:
            base, owner = key.rsplit("@", 1)
            if owner != trace_name:
                continue
            p = dict(p, key_path=base)
        keep.append(k)
        params.append(p)
    out = dict(cal, parameters=params, covariance=[[cal["covariance"][i][j] for j in keep] for i in keep])
    own = next((t for t in cal.get("traces", []) if t["name"] == trace_name), None)
    if own:
        out["channels"] = [dict(c, noise=dict(c["noise"], band_multiplier=o["noise"]["band_multiplier"],
                                              band_quantile=o["noise"]["band_quantile"]))
                           for c, o in zip(cal["channels"], own["channels"])]
    out["traces"] = []
    if own_noise:
        t = {"band_multiplier": cal["fit"]["t975"], "band_quantile": "t"}
        out["channels"] = [dict(cal["channels"][0], noise=dict(cal["channels"][0]["noise"], **own_noise, **t))]
    with open(path, "w") as fh:
        json.dump(out, fh)
    return path


def rows_errors(fit_csv, t0=None, t1=None, node="sump", gauss=None, trace=None):
    """Sump RMSE, bias and the fraction inside the 95 % band over the rows from t0 (s) on, before
    t1 (s) when given (of the trace `trace` in a stacked fit.csv); with `gauss` (Student's t over the band's multiplier) also the fraction
    inside the Gaussian band (`inside_gauss95`: the band's standard deviation times t)."""
    n = s2 = s1 = inside = ing = 0
    with open(fit_csv) as fh:
        for x in csv.DictReader(fh):
            t = float(x["time_s"])
            if (t0 is not None and t < t0) or (t1 is not None and t >= t1) or (trace and x["trace"] != trace):
                continue
            r = float(x[f"{node}_residual_k"])
            n += 1
            s2 += r * r
            s1 += r
            inside += abs(r) <= float(x[f"{node}_band95_k"])
            ing += abs(r) <= float(x[f"{node}_band95_k"]) * (gauss or 1.0)
    if n == 0:
        return {"rows": 0}
    out = {"rows": n, "rmse_k": math.sqrt(s2 / n), "bias_k": s1 / n, "inside_band95": inside / n}
    if gauss:
        out["inside_gauss95"] = ing / n
    return out


def multiplier(cal, trace_name=None):
    """The band multiplier of a calibration.json's (only) channel: of the trace `trace_name` when
    it has one, else the channel's."""
    own = next((t for t in cal.get("traces", []) if t["name"] == trace_name), None)
    return (own or cal)["channels"][0]["noise"]["band_multiplier"]


def predict(bin_, model, trace, band, out, extra=()):
    run([bin_, "calibrate", model, "--trace", trace, "--holdout", "0:1e9", "--band-from", band, "--out", out,
         *extra])
    return os.path.join(out, "fit.csv")


def whole(fit_csv, t975=None, t0=None, t1=None):
    """The prediction run's figures over its rows (from t0, before t1, s; the whole trace by
    default), with the Gaussian band's (Student's `t975` of the fit over the run's multiplier)."""
    cal = json.load(open(os.path.join(os.path.dirname(fit_csv), "calibration.json")))
    node = cal["channels"][0]["node"]
    gauss = t975 / multiplier(cal) if t975 else None
    return rows_errors(fit_csv, t0, t1, node=node, gauss=gauss)


def own_band(bin_, tr, d, cal, turbine, rows):
    """`turbine`'s held-out spring days and its summer predicted again with the band of its own
    residual process (band_json's `own_noise`); the fraction inside it added to `rows` (the
    spring prediction runs from the trace's start, as the fit does: its RMSE is the fit's)."""
    spring, summer = f"{turbine}_2017-spring", f"{turbine}_2016-summer"
    model = os.path.join(d, f"calibrated_{spring}.toml")
    node = cal["channels"][0]["node"]
    noise = own_ar1(os.path.join(d, "fit.csv"), spring, node)
    band = band_json(cal, turbine, spring, os.path.join(d, f"band_own_{turbine}.json"), own_noise=noise)
    # A spring trace with summer days appended (--train-summer) has several segments.
    several = rows_errors(os.path.join(d, "fit.csv"), HELD[1], trace=spring)["rows"] > 0
    f = predict(bin_, model, os.path.join(tr, f"{spring}.csv"), band, os.path.join(d, f"predict_own_{spring}"),
                ["--segment", "all"] if several else [])
    held = rows_errors(f, *HELD, node=node)
    fitted = rows_errors(f, None, HELD[0], node=node)
    # The own process's band is Gaussian (band_json): its coverage is `inside_band95` here.
    f = predict(bin_, model, os.path.join(tr, f"{summer}.csv"), band, os.path.join(d, f"predict_own_{summer}"))
    for x, e in zip(rows, [fitted, held, whole(f)]):
        x["inside_own_band95"] = e["inside_band95"]
        x["rmse_own_run_k"] = e["rmse_k"]
    return noise


def run_dir(out, name):
    """The output directory of the fit `name`."""
    return os.path.join(out, name.replace(" ", "_").replace(",", "").replace("/", "_per_"))


def one_fit(bin_, trs, name, sp, out):
    """Run the calibration `sp` (see spec), predict the other rows, return its figures."""
    d = run_dir(out, name)
    fit, turbines, sets, tr = sp["fit"], sp["turbines"], sp["sets"], trs[sp["kind"]]
    cmd = [bin_, "calibrate", sp["model"](d) if callable(sp["model"]) else sp["model"]]
    for t in turbines:
        cmd += ["--trace", os.path.join(tr, f"{t}_2017-spring.csv")]
    for f in fit:
        cmd += ["--fit", f]
    for s in sets:
        cmd += ["--set", s]
    cmd += ["--holdout", HOLDOUT, "--max-iterations", "60", "--gearbox-kind", "wind-turbine", "--rated=1680:-11600",
            "--out", d]
    before, t0 = os.times(), time.monotonic()
    run(cmd)
    after = os.times()
    cal = json.load(open(os.path.join(d, "calibration.json")))
    res = {"name": name, "wall_s": time.monotonic() - t0,
           "cpu_s": after.children_user - before.children_user + after.children_system - before.children_system,
           "evaluations": cal["fit"]["evaluations"], "stop": cal["fit"]["stop"],
           "parameters": [{k: p[k] for k in ("key_path", "value", "ci95_low", "ci95_high")} for p in cal["parameters"]],
           "noise": cal["channels"][0]["noise"], "rows": [], "t975": cal["fit"]["t975"],
           "multipliers": {t["name"]: t["channels"][0]["noise"]["band_multiplier"] for t in cal.get("traces", [])},
           "own_noise": {}, "weakest": min(cal["identifiability"], key=lambda e: e["relative_eigenvalue"]),
           "rated": {t["name"]: t["plausibility"]["rated"] for t in cal.get("traces", []) if t.get("plausibility")}}
    if cal.get("plausibility"):
        res["rated"][turbines[0]] = cal["plausibility"]["rated"]
    by_trace = {t["name"].split("_")[0]: t for t in cal.get("traces", [])}
    node = cal["channels"][0]["node"]
    for turbine in ["R80711", "R80721"]:
        spring, summer = f"{turbine}_2017-spring", f"{turbine}_2016-summer"
        if turbine in turbines:
            own = len(turbines) > 1
            model = os.path.join(d, f"calibrated_{spring}.toml" if own else "calibrated.toml")
            band = band_json(cal, turbine, spring, os.path.join(d, f"band_{turbine}.json")) if own else \
                os.path.join(d, "calibration.json")
            ch = (by_trace[turbine]["channels"][0] if own else cal["channels"][0])
            gauss = cal["fit"]["t975"] / ch["noise"]["band_multiplier"]
            fc = os.path.join(d, "fit.csv")
            g = [rows_errors(fc, a, b, node=node, gauss=gauss, trace=spring if own else None)["inside_gauss95"]
                 for a, b in ((None, HELD[0]), HELD)]
            if summer_fitted(fc, spring, own):
                for a, b, w in ((None, HELD[0], "spring 2017 days 1–14 (fitted)"),
                                (HELD[1], None, "summer days (fitted)")):
                    res["rows"].append(dict(rows_errors(fc, a, b, node=node, gauss=gauss, trace=spring),
                                            trace=f"{turbine} {w}"))
            label = "fitted rows (spring and summer days)" if len(res["rows"]) and "summer days" in \
                res["rows"][-1]["trace"] else "spring 2017 days 1–14 (fitted)"
            res["rows"].append(dict(ch["fitted"], inside_gauss95=g[0], trace=f"{turbine} {label}",
                                    key=f"{turbine} spring 2017 days 1–14"))
            res["rows"].append(dict(ch["holdout"], inside_gauss95=g[1], trace=f"{turbine} spring 2017 days 15–27 (held out)",
                                    key=f"{turbine} spring 2017 days 15–27"))
        else:
            model, band = os.path.join(d, "calibrated.toml"), os.path.join(d, "calibration.json")
            f = predict(bin_, model, os.path.join(tr, f"{spring}.csv"), band, os.path.join(d, f"predict_{spring}"))
            t975 = cal["fit"]["t975"]
            res["rows"].append(dict(whole(f, t975, None, HELD[0]), trace=f"{turbine} spring 2017 days 1–14 (predicted)",
                                    key=f"{turbine} spring 2017 days 1–14"))
            res["rows"].append(dict(whole(f, t975, *HELD), trace=f"{turbine} spring 2017 days 15–27 (predicted)",
                                    key=f"{turbine} spring 2017 days 15–27"))
            res["rows"].append(dict(whole(f, t975), trace=f"{turbine} spring 2017 days 1–27 (predicted)"))
        f = predict(bin_, model, os.path.join(tr, f"{summer}.csv"), band, os.path.join(d, f"predict_{summer}"))
        res["rows"].append(dict(whole(f, cal["fit"]["t975"]), trace=f"{turbine} summer 2016 (predicted)",
                                key=f"{turbine} summer 2016"))
        if turbine in turbines and len(turbines) > 1 and len(cal["channels"]) == 1:
            res["own_noise"][spring] = own_band(bin_, tr, d, cal, turbine, res["rows"][-3:])
    return res


def summer_fitted(fit_csv, trace, own):
    """Whether the trace `trace` of a fit of both turbines has fitted rows after the held-out
    window (--train-summer)."""
    if not own:
        return False
    with open(fit_csv) as fh:
        return any(x["trace"] == trace and float(x["time_s"]) >= HELD[1] for x in csv.DictReader(fh))


def residual_analysis(fit_csv, trace_csv, trace_name, window=18, node="sump"):
    """Where a trace's fitted-row sump residuals (simulated − measured) come from: their RMSE
    split into a slow part (the difference of the simulated and measured centred means over
    `window` rows, 3 h) and a fast part (the rest), the measured sump's own scatter about its
    centred mean (what no model without the fan's phase can follow), and the residual's bias and
    RMSE by measured-sump, power and outdoor-temperature bins, and the least-squares slope of the
    residual on the outdoor temperature (what a warmer season would shift it by)."""
    inputs, outdoor = {}, {}
    with open(trace_csv) as fh:
        for x in csv.DictReader(fh):
            inputs[x["time_s"]] = -float(x["input_torque_nm"]) * float(x["input_speed_rpm"]) * math.pi / 30e3
            outdoor[x["time_s"]] = float(x["boundary:outdoor"])
    with open(fit_csv) as fh:
        rows = [x for x in csv.DictReader(fh) if x["trace"] == trace_name]
    meas = [float(x[f"{node}_measured_c"]) for x in rows]
    sim = [float(x[f"{node}_simulated_c"]) for x in rows]
    out = []
    for i, x in enumerate(rows):
        if x["holdout"] != "0":
            continue
        lo, hi = max(0, i - window // 2), min(len(rows), i + window // 2 + 1)
        mm, ms = sum(meas[lo:hi]) / (hi - lo), sum(sim[lo:hi]) / (hi - lo)
        out.append({"r": sim[i] - meas[i], "slow": ms - mm, "fast": (sim[i] - ms) - (meas[i] - mm),
                    "own": meas[i] - mm, "meas": meas[i], "power_kw": inputs[x["time_s"]],
                    "outdoor_c": outdoor[x["time_s"]]})
    rms = lambda k, xs=out: math.sqrt(sum(x[k] ** 2 for x in xs) / len(xs))
    print(f"  {trace_name}, fitted rows ({len(out)}): sump RMSE {rms('r'):.2f} K = slow {rms('slow'):.2f} K ⊕ "
          f"fast {rms('fast'):.2f} K ({window * 10} min centred means); the measured sump's scatter about its "
          f"own centred mean {rms('own'):.2f} K")
    fitted = [i for i in range(1, len(rows)) if rows[i]["holdout"] == "0" and rows[i - 1]["holdout"] == "0"]
    print(f"  rows where the sump rises by more than 3 K from the row before: simulated "
          f"{sum(sim[i] - sim[i - 1] > 3.0 for i in fitted)}, measured {sum(meas[i] - meas[i - 1] > 3.0 for i in fitted)}")
    labels = {"meas": "measured sump, °C", "power_kw": "power, kW", "outdoor_c": "outdoor air, °C"}
    for key, edges in (("meas", [30, 45, 50, 55, 56, 57, 58, 59, 61]), ("power_kw", [-100, 0, 50, 200, 500, 2100]),
                       ("outdoor_c", [-10, 5, 10, 15, 20, 25, 40])):
        cells = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            xs = [x for x in out if lo <= x[key] < hi]
            if xs:
                cells.append(f"[{lo}, {hi}): {len(xs)} rows, {sum(x['r'] for x in xs) / len(xs):+.2f} / {rms('r', xs):.2f}")
        print(f"  by {labels[key]} (bias / RMSE, K): " + "; ".join(cells))
    n = len(out)
    mx, my = sum(x["outdoor_c"] for x in out) / n, sum(x["r"] for x in out) / n
    slope = sum((x["outdoor_c"] - mx) * (x["r"] - my) for x in out) / sum((x["outdoor_c"] - mx) ** 2 for x in out)
    for lo, hi, w in ((None, HELD[0], "spring days 1–14"), (HELD[1], None, "summer days")):
        xs = [x for x, row in zip(out, (r for r in rows if r["holdout"] == "0"))
              if (lo is None or float(row["time_s"]) >= lo) and (hi is None or float(row["time_s"]) < hi)]
        if xs and len(xs) < len(out):
            print(f"  {w}: {len(xs)} fitted rows, mean outdoor air {sum(x['outdoor_c'] for x in xs) / len(xs):.1f} °C, "
                  f"sump RMSE {rms('r', xs):.2f} K, bias {sum(x['r'] for x in xs) / len(xs):+.2f} K")
    summer = trace_csv.replace("2017-spring", "2016-summer")
    with open(summer) as fh:
        ts = [float(x["boundary:outdoor"]) for x in csv.DictReader(fh)]
    ms = sum(ts) / len(ts)
    print(f"  residual against the outdoor air (least squares): {slope:+.3f} K/K about {my:+.2f} K at its mean "
          f"{mx:.1f} °C; at summer 2016's mean outdoor air ({ms:.1f} °C, its inputs only) that line gives "
          f"{my + slope * (ms - mx):+.2f} K")


def print_fit(r):
    """One fit's residual processes and its table (the band of the fit's residual process, and for a
    fit of both turbines that of each turbine's own beside it)."""
    n = r["noise"]
    print(f"  sump residuals (fitted rows): φ {n['phi']:.3f}, σ_a {n['innovation_sd_k']:.3f} K, band multiplier "
          f"{n['band_multiplier']:.3f} ({n['band_quantile']}; t {r['t975']:.3f})"
          + "".join(f", {t} {m:.3f}" for t, m in r["multipliers"].items()))
    w = r["weakest"]
    comp = ", ".join(f"{c['component']:+.2f} ln {c['key_path']}" for c in w["components"] if abs(c["component"]) >= 0.1)
    print(f"  least determined direction ({w['status']}, relative eigenvalue {w['relative_eigenvalue']:.2g}, "
          f"±{w['ci95_half_width']:.2f} in ln, 95 %): {comp}")
    for t, x in r["rated"].items():
        src = ", ".join(f"{k} {w / 1e3:.1f}" for k, w in x["loss_by_source_w"] if w >= 50)
        print(f"  rated point ({x['power_w'] / 1e3:.0f} kW, oil {x['oil_temp_c']:.1f} °C, {t}'s model): loss "
              f"{x['loss_total_w'] / 1e3:.1f} kW ({src} kW), efficiency {x['efficiency']:.3f}")
    for t, m in r.get("own_noise", {}).items():
        print(f"  {t}'s fitted rows alone: φ {m['phi']:.3f}, σ_a {m['innovation_sd_k']:.3f} K")
    print("| trace | rows | sump RMSE, K | bias, K | inside the 95 % band | inside the Gaussian band (t) | "
          "inside the Gaussian band of the turbine's own residual process |")
    print("|---|---|---|---|---|---|---|")
    for x in r["rows"]:
        own = f"{100 * x['inside_own_band95']:.1f} %" if "inside_own_band95" in x else "—"
        gauss = f"{100 * x['inside_gauss95']:.1f} %" if "inside_gauss95" in x else "—"
        print(f"| {x['trace']} | {x['rows']} | {x['rmse_k']:.2f} | {x['bias_k']:+.2f} | "
              f"{100 * x['inside_band95']:.1f} % | {gauss} | {own} |")
    print(flush=True)


def print_summary(results):
    """docs/validation.md's table: per trace and fit, RMSE / bias / inside the band [inside the
    Gaussian band] (the Gaussian band of the turbine's own residual process in brackets where there
    is one)."""
    if not results:
        return
    names = [r["name"] for r in results]
    print("| trace | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    keys = [f"{t} {p}" for t in ("R80711", "R80721")
            for p in ("spring 2017 days 1–14", "spring 2017 days 15–27", "summer 2016")]
    for key in keys:
        cells = []
        for r in results:
            y = next(x for x in r["rows"] if x.get("key") == key)
            own = f" ({100 * y['inside_own_band95']:.1f} %)" if "inside_own_band95" in y else ""
            gauss = f" [{100 * y['inside_gauss95']:.1f} %]" if "inside_gauss95" in y else ""
            cells.append(f"{y['rmse_k']:.2f} / {y['bias_k']:+.2f} / {100 * y['inside_band95']:.1f} %{gauss}{own}")
        print(f"| {key} | " + " | ".join(cells) + " |")
    print()


def print_variants(results):
    """docs/validation.md's table of the variants: sump RMSE on both turbines' fitted days,
    held-out days and summer, R80721's band coverage [that of the Gaussian band t·sd], the parameters
    at a bound."""
    print("| variant | R80711 fitted / held out / summer, K | R80721 fitted / held out / summer, K | "
          "R80721 inside the band (held out / summer) [Gaussian band] | no interval (at a bound or not determined) |")
    print("|---|---|---|---|---|")
    for r in results:
        x = {y["key"]: y for y in r["rows"] if "key" in y}
        cell = lambda t: " / ".join(f"{x[f'{t} {p}']['rmse_k']:.2f}" for p in
                                    ("spring 2017 days 1–14", "spring 2017 days 15–27", "summer 2016"))
        keys = [f"R80721 {p}" for p in ("spring 2017 days 15–27", "summer 2016")]
        bands = " / ".join(f"{100 * x[k]['inside_band95']:.1f} %" for k in keys) + " [" + \
            " / ".join(f"{100 * x[k]['inside_gauss95']:.1f} %" for k in keys) + "]"
        bound = ", ".join(p["key_path"].split(".")[-1] for p in r["parameters"] if p["ci95_low"] is None) or "–"
        print(f"| {r['name']} | {cell('R80711')} | {cell('R80721')} | {bands} | {bound} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default="../shared/data/engie_la_haute_borne")
    ap.add_argument("--out", default="/tmp/geartherm_turbines")
    ap.add_argument("--bin", default="target/release/geartherm")
    ap.add_argument("--only", help="run only the fit of this name")
    ap.add_argument("--variants", action="store_true", help="run the variants tried instead of the fits")
    ap.add_argument("--residuals", action="store_true",
                    help="also print where each two-turbine fit's residuals on the fitted days come from")
    ap.add_argument("--train-summer", type=int, metavar="YEAR",
                    help="also fit each turbine's first 14 complete days from 1 July of YEAR (see above)")
    a = ap.parse_args()
    runs = variants() if a.variants else FITS
    if a.train_summer and (a.variants or any(sp["kind"] != "sump" for sp in runs.values())):
        sys.exit("--train-summer: only with the fits of the sump traces (not --variants)")
    trs = traces(a.data, a.out, {sp["kind"] for sp in runs.values()}, a.train_summer)
    load0 = os.getloadavg()[0]
    results = []
    for name, sp in runs.items():
        if a.only and a.only != name:
            continue
        r = one_fit(a.bin, trs, name, sp, a.out)
        results.append(r)
        print(f"## {name}: {r['evaluations']} evaluations (stop: {r['stop']}), wall {r['wall_s']:.1f} s, "
              f"CPU {r['cpu_s']:.1f} s")
        for p in r["parameters"]:
            ci = "no interval (at a bound or not determined)" if p["ci95_low"] is None else \
                f"[{p['ci95_low']:.4g}, {p['ci95_high']:.4g}]"
            print(f"  {p['key_path']}: {p['value']:.4g} {ci}")
        print_fit(r)
        if a.residuals and len(sp["turbines"]) > 1:
            d = run_dir(a.out, name)
            nodes = [c["node"] for c in json.load(open(os.path.join(d, "calibration.json")))["channels"]]
            for t in ("R80711_2017-spring", "R80721_2017-spring"):
                residual_analysis(os.path.join(d, "fit.csv"), os.path.join(trs[sp["kind"]], f"{t}.csv"), t,
                                  node="sump" if "sump" in nodes else nodes[0])
            print()
    print_summary(results) if not a.variants else print_variants(results)
    print(f"load {load0:.1f} before, {os.getloadavg()[0]:.1f} after")
    stem = "figures_variants" if a.variants else "figures"
    with open(os.path.join(a.out, stem + ("_one.json" if a.only else ".json")), "w") as fh:
        json.dump(results, fh, indent=2)


if __name__ == "__main__":
    main()
