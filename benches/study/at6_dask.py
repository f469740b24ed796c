"""The AT6 1000-case Latin-hypercube study of models/studies/at6_wltc_lhs.toml through Python on a
distributed.LocalCluster, timed, and compared value by value with the CLI's study.csv.

    geartherm study models/studies/at6_wltc_lhs.toml --out studies/at6_wltc_lhs
    python3 benches/study/at6_dask.py studies/at6_wltc_lhs/study.csv [workers] [first_n_cases]
"""

import csv
import math
import sys
import time
import tomllib
from pathlib import Path

import geartherm
from distributed import Client, LocalCluster

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "models" / "studies" / "at6_wltc_lhs.toml"


def main() -> None:
    cli_csv = Path(sys.argv[1])
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    first = int(sys.argv[3]) if len(sys.argv) > 3 else None
    spec = tomllib.loads(STUDY.read_text())
    model = geartherm.Model.load(STUDY.parent / spec["study"]["model"])
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cl, Client(cl) as client:
        t0 = time.perf_counter()
        df = geartherm.study(model, spec["parameters"], spec["job"], spec["sampling"], client=client, threads_per_task=1,
                              cases=None if first is None else range(first))
        wall = time.perf_counter() - t0
    print(f"{len(df)} cases on a {workers}-worker LocalCluster in {wall:.1f} s: {len(df) / wall:.2f} cases/s")
    df.to_pickle(Path("/tmp") / f"at6_dask_{len(df)}.pkl")
    while not cli_csv.exists():  # the CLI study may still be running
        time.sleep(10)
    with cli_csv.open() as f:
        rows = list(csv.DictReader(f))
    rows = rows[: len(df)]
    assert len(rows) == len(df), (len(rows), len(df))
    cols = [c for c in df.columns if c not in ("message",)]
    diff = 0
    for r, (_, d) in zip(rows, df.iterrows()):
        for c in cols:
            a, b = r[c], d[c]
            if isinstance(b, float):
                x = float(a) if a != "" else math.nan
                same = (x == b) or (math.isnan(x) and math.isnan(b))
            else:
                same = str(b) == a
            diff += not same
    print(f"compared {len(rows)} rows x {len(cols)} columns with {cli_csv}: {diff} differences")
    sys.exit(1 if diff else 0)


if __name__ == "__main__":
    main()
