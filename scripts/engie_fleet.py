#!/usr/bin/env python3
"""The fleet case: the MM82 sump model (validation/engie_la_haute_borne/mm82_sump_only.toml)
fitted in one calibration to every row of both La Haute Borne records, R80711 and R80721
(../shared/data/engie_la_haute_borne/R807*_2013-2020.csv: 2013-06 … 2018-01, 84 156 rows, 44
segments), with one churning multiplier shared by the two turbines (the loss level) and a
cooler capacity rate per turbine (docs/calibration.md, "Several traces"; the figures in
docs/validation.md and docs/performance.md).

    python3 scripts/engie_fleet.py [--data DIR] [--out DIR] [--bin PATH] [--set KEY=VALUE ...]

`--set` (repeatable) is passed to `calibrate` (e.g. `--set 'losses.churning="seetharaman"'
--set losses.multiplier.churning=30.0`: Seetharaman and Kahraman's churning law, the law of the
two-turbine fit in docs/validation.md, started from a multiplier of 30).

Builds the two traces with scripts/engie_traces.py under OUT/traces (default OUT
/tmp/geartherm_fleet), runs the one `geartherm calibrate` command and prints its wall time, the
CPU time (user + sys) of the command, the load average before and after, the fitted values with
their intervals, and per turbine the sump RMSE and the fraction of rows inside the 95 % band.
Writes OUT/figures.json.
"""
import argparse
import json
import os
import subprocess
import sys
import time

MODEL = "validation/engie_la_haute_borne/mm82_sump_only.toml"
RECORDS = ["R80711_2013-2020", "R80721_2013-2020"]
FIT = [
    "losses.multiplier.churning=0.01:100",
    'thermal.coolers["oil_cooler"].capacity_rate_w_per_k@*=100:30000',
]


def traces(data, out):
    src = os.path.join(out, "records")
    os.makedirs(src, exist_ok=True)
    for r in RECORDS:
        link = os.path.join(src, r + ".csv")
        if not os.path.exists(link):
            os.symlink(os.path.abspath(os.path.join(data, r + ".csv")), link)
    subprocess.run([sys.executable, "scripts/engie_traces.py", src, os.path.join(out, "traces")], check=True,
                   stdout=subprocess.DEVNULL)
    return [os.path.join(out, "traces", r + ".csv") for r in RECORDS]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default="../shared/data/engie_la_haute_borne")
    ap.add_argument("--out", default="/tmp/geartherm_fleet")
    ap.add_argument("--bin", default="target/release/geartherm")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    a = ap.parse_args()
    files = traces(a.data, a.out)
    cmd = [a.bin, "calibrate", MODEL]
    for f in files:
        cmd += ["--trace", f]
    for f in FIT:
        cmd += ["--fit", f]
    for v in a.set:
        cmd += ["--set", v]
    cmd += ["--max-iterations", "80", "--out", os.path.join(a.out, "fit")]
    load0 = os.getloadavg()
    before = os.times()
    t0 = time.monotonic()
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    after = os.times()
    load1 = os.getloadavg()
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    s = json.load(open(os.path.join(a.out, "fit", "calibration.json")))
    figures = {
        "wall_s": wall,
        "cpu_s": cpu,
        "load_before": load0[0],
        "load_after": load1[0],
        "cores": os.cpu_count(),
        "rows": s["rows"],
        "evaluations": s["fit"]["evaluations"],
        "stop": s["fit"]["stop"],
        "parameters": [
            {k: p[k] for k in ("key_path", "value", "ci95_low", "ci95_high", "ci95_independent_low",
                               "ci95_independent_high")}
            for p in s["parameters"]
        ],
        "traces": [
            {"name": t["name"], "segments": len(t["segments"]), "rows": t["rows"],
             "rmse_k": t["channels"][0]["fitted"]["rmse_k"],
             "inside_band95": t["channels"][0]["fitted"]["inside_band95"]}
            for t in s["traces"]
        ],
        "noise": s["channels"][0]["noise"],
    }
    with open(os.path.join(a.out, "figures.json"), "w") as fh:
        json.dump(figures, fh, indent=2)
    print(f"{s['rows']} rows, {sum(t['segments'] for t in figures['traces'])} segments, "
          f"{figures['evaluations']} evaluations (stopped on {figures['stop']})")
    print(f"wall {wall:.1f} s, CPU (user+sys) {cpu:.1f} s, load {load0[0]:.1f} before, {load1[0]:.1f} after, "
          f"{os.cpu_count()} cores")
    for p in figures["parameters"]:
        if p["ci95_low"] is None:
            print(f"  {p['key_path']}: {p['value']:.4g} (no interval: at a bound or not influenced)")
            continue
        print(f"  {p['key_path']}: {p['value']:.4g} [{p['ci95_low']:.4g}, {p['ci95_high']:.4g}] "
              f"(independent errors [{p['ci95_independent_low']:.4g}, {p['ci95_independent_high']:.4g}])")
    for t in figures["traces"]:
        print(f"  {t['name']}: {t['segments']} segments, {t['rows']} rows, sump RMSE {t['rmse_k']:.2f} K, "
              f"{100 * t['inside_band95']:.1f} % inside the 95 % band")
    n = figures["noise"]
    print(f"  sump residuals: φ {n['phi']:.3f}, σ_a {n['innovation_sd_k']:.3f} K, "
          f"acf lag 1, 2, 6: {', '.join(f'{x:.3f}' for x in n['autocorrelation_lag_1_2_6'])}")


if __name__ == "__main__":
    main()
