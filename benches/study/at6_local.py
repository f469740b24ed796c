"""The AT6 1000-case Latin-hypercube study of models/studies/at6_wltc_lhs.toml through Python's
local backend (the runner `geartherm study` uses, on this machine's cores), timed: wall time,
cases per second, and the process's CPU time per case (user + sys of every thread), from which
the rate of two free cores follows.

    python3 benches/study/at6_local.py [OUT_DIR]
"""

import resource
import sys
import time
from pathlib import Path

import geartherm

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "models" / "studies" / "at6_wltc_lhs.toml"


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else None
    s = geartherm.Study.load(STUDY)
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    df = s.run(out=out, progress=False)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    n = s.tally["solved"]
    print(f"{n} cases in {wall:.2f} s: {n / wall:.1f} cases/s on {s.tally['threads']} threads")
    print(f"CPU {cpu:.2f} s: {1e3 * cpu / max(n, 1):.2f} ms per case, {2 * max(n, 1) / cpu:.0f} cases/s on 2 free cores")
    print(f"{(df.status == 'ok').sum()} ok of {len(df)}")


if __name__ == "__main__":
    main()
