#!/usr/bin/env python3
"""Extract of Engie's "La Haute Borne" SCADA data (turbines R80711 and R80721) for the
calibration study of docs/validation.md ("Wind-turbine gearbox: Engie La Haute Borne").

Reads the per-turbine CSV files of the folder datasets/2020_wind_engine/ of the public GitHub
repository travisdesell/exact (a local copy of that folder: SRC) and writes, for the two periods
below and the two turbines, the columns the calibration needs into OUT (one CSV per turbine and
period, the source's column names and units, rows as in the source). Nothing is fetched.

    python3 scripts/engie_extract.py SRC OUT
"""
import csv
import glob
import os
import sys

TURBINES = ["R80711", "R80721"]
# (name, first, last) of each period, local time as in the source's Date_time.
PERIODS = [
    ("2017-spring", "2017-03-30T03:50", "2017-04-26T07:20"),
    ("2016-summer", "2016-07-28T07:50", "2016-08-17T07:50"),
]
COLUMNS = ["Date_time", "P_avg", "Ds_avg", "Rs_avg", "Cm_avg", "Gost_avg", "Git_avg",
           "Gb1t_avg", "Gb2t_avg", "Yt_avg", "Ot_avg"]


def rows_of(src, turbine):
    for path in sorted(glob.glob(os.path.join(src, f"turbine_{turbine}_*.csv"))):
        with open(path, newline="") as fh:
            reader = csv.DictReader(fh)
            for row in reader:
                yield os.path.basename(path), row


def main(src, out):
    os.makedirs(out, exist_ok=True)
    for turbine in TURBINES:
        rows = list(rows_of(src, turbine))
        for name, first, last in PERIODS:
            keep = [(f, r) for f, r in rows if first <= r["Date_time"][:16] <= last]
            keep.sort(key=lambda fr: fr[1]["Date_time"])
            files = sorted({f for f, _ in keep})
            dest = os.path.join(out, f"{turbine}_{name}.csv")
            with open(dest, "w", newline="") as fh:
                fh.write(f"# {turbine}, {name}: rows {first} .. {last} of {', '.join(files)}\n")
                w = csv.writer(fh, lineterminator="\n")
                w.writerow(COLUMNS)
                for _, r in keep:
                    w.writerow([r[c] for c in COLUMNS])
            print(f"{dest}: {len(keep)} rows from {', '.join(files)}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
