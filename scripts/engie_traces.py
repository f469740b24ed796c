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

    python3 scripts/engie_traces.py EXTRACT_DIR OUT_DIR

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


def main(src, out):
    os.makedirs(out, exist_ok=True)
    for path in sorted(glob.glob(os.path.join(src, "R807*_*.csv"))):
        r = rows(path)
        t0 = datetime.fromisoformat(r[0]["Date_time"]).timestamp()
        ratio = statistics.median(
            float(x["Ds_avg"]) / float(x["Rs_avg"]) for x in r if float(x["Rs_avg"]) > 8.0
        )
        dest = os.path.join(out, os.path.basename(path))
        with open(dest, "w") as fh:
            fh.write("time_s,input_speed_rpm,input_torque_nm,gear,boundary:nacelle,boundary:outdoor,node:sump\n")
            for x in r:
                t = datetime.fromisoformat(x["Date_time"]).timestamp() - t0
                n = max(float(x["Ds_avg"]), 0.0)
                w = n * math.pi / 30.0
                torque = -float(x["P_avg"]) * 1e3 / w if n > 50.0 else 0.0
                fh.write(f"{t:.0f},{n},{torque:.1f},run,{x['Yt_avg']},{x['Ot_avg']},{x['Gost_avg']}\n")
        print(f"{dest}: {len(r)} rows, ratio Ds/Rs {ratio:.3f}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
