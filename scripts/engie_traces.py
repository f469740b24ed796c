#!/usr/bin/env python3
"""geartherm traces from the La Haute Borne extract (scripts/engie_extract.py):

    time_s            seconds since the extract's first row (Date_time, converted to UTC)
    input_speed_rpm   generator speed Ds_avg (the model's input is the high-speed shaft), >= 0
    input_torque_nm   -P_avg / ω_generator: the electrical power carried back through the
                      gearbox from the rotor (negative: power flows from the output to the
                      input); 0 below 50 rpm
    gear              run
    boundary:nacelle  nacelle temperature Yt_avg, °C
    boundary:outdoor  outdoor temperature Ot_avg, °C
    node:sump         gearbox oil sump temperature Gost_avg, °C
  with --channels also (models/mm82_wind_gearbox.toml has these nodes; the single-node
  variant validation/engie_la_haute_borne/mm82_sump_only.toml does not):
    node:inlet          gearbox oil inlet temperature Git_avg, °C
    node:hss_bearing_1  gearbox bearing temperature Gb1t_avg, °C
    node:hss_bearing_2  gearbox bearing temperature Gb2t_avg, °C

    python3 scripts/engie_traces.py [--channels] EXTRACT_DIR OUT_DIR

Reads the extracts and the full records (R80711_2013-2020.csv, …, in
../shared/data/engie_la_haute_borne/ from the repository root). A source cell that is empty
stays empty in the trace (a missing value: `geartherm calibrate` and `geartherm trace` drop
such rows and count them, or refuse them with --refuse-missing); the record's gaps in time stay
gaps (the trace reader cuts the trace into segments there).

Also prints the overall ratio Ds_avg / Rs_avg (median over rows with the rotor above 8 rpm).
"""
import csv
import glob
import math
import os
import statistics
import sys
from datetime import datetime


def rows(path):
    with open(path) as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def number(x, key):
    """The cell as a float, None when it is empty."""
    v = (x.get(key) or "").strip()
    return float(v) if v else None


def inputs(x):
    """(speed rpm, torque N·m) as text, empty where a source cell is."""
    ds, p = number(x, "Ds_avg"), number(x, "P_avg")
    if ds is None or p is None:
        return "", ""
    n = max(ds, 0.0)
    w = n * math.pi / 30.0
    torque = -p * 1e3 / w if n > 50.0 else 0.0
    return f"{n}", f"{torque:.1f}"


# Measured node columns: (trace column, extract column).
SUMP = [("node:sump", "Gost_avg")]
CHANNELS = SUMP + [("node:inlet", "Git_avg"), ("node:hss_bearing_1", "Gb1t_avg"), ("node:hss_bearing_2", "Gb2t_avg")]


def main(src, out, measured=SUMP):
    os.makedirs(out, exist_ok=True)
    for path in sorted(glob.glob(os.path.join(src, "R807*_*.csv"))):
        r = rows(path)
        t0 = datetime.fromisoformat(r[0]["Date_time"]).timestamp()
        pairs = [(number(x, "Ds_avg"), number(x, "Rs_avg")) for x in r]
        ratio = statistics.median(ds / rs for ds, rs in pairs if ds is not None and rs is not None and rs > 8.0)
        dest = os.path.join(out, os.path.basename(path))
        empty = 0
        with open(dest, "w") as fh:
            names = ",".join(c for c, _ in measured)
            fh.write(f"time_s,input_speed_rpm,input_torque_nm,gear,boundary:nacelle,boundary:outdoor,{names}\n")
            for x in r:
                t = datetime.fromisoformat(x["Date_time"]).timestamp() - t0
                n, torque = inputs(x)
                cells = [n, torque, (x["Yt_avg"] or "").strip(), (x["Ot_avg"] or "").strip()]
                cells += [(x[k] or "").strip() for _, k in measured]
                empty += any(c == "" for c in cells)
                fh.write(f"{t:.0f},{cells[0]},{cells[1]},run," + ",".join(cells[2:]) + "\n")
        print(f"{dest}: {len(r)} rows ({empty} with an empty cell), ratio Ds/Rs {ratio:.3f}")


if __name__ == "__main__":
    args = sys.argv[1:]
    channels = "--channels" in args
    args = [a for a in args if a != "--channels"]
    if len(args) != 2:
        sys.exit(__doc__)
    main(args[0], args[1], CHANNELS if channels else SUMP)
