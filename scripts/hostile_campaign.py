#!/usr/bin/env python3
"""Hostile-input campaign: generated invalid or extreme inputs through every command and the
Python API, counting what must never happen.

    python3 scripts/hostile_campaign.py --cases 100000 --jobs 2 [--bin target/release/geartherm]
        [--python PYTHON] [--families cli,set,...] [--seed N]

Families (share of the cases; modules under scripts/hostile/):

| family | what | module |
|---|---|---|
| cli | mutated and extreme model files, generated cycles, malformed and extreme options on `check`, `info`, `losses`, `steady`, `map`, `run`, `rating` | cli.py |
| set | `--set` key paths (real, mutated, malformed) and values (hostile numbers and types, malformed TOML) on every model-reading command, `bench` included | cli.py |
| study_spec | generated study files: plans, parameters, jobs, outputs, names, model paths; `--list`, `--shard`, default output directory; a directory holding another study | study.py |
| study_kill | a study SIGKILLed at a random moment, then resumed | study.py |
| study_two | two writers into one study directory at once (the same study; two shards), then a merge | study.py |
| study_huge | grids and samples at and beyond the plan's limits | study.py |
| stdio | stdout or stderr on /dev/full, a closed pipe, a read-only descriptor, closed | stdio.py |
| report | crafted run, map and bench directories given to `report` | report.py |
| uq | generated `[uncertainty]` sections (model or study file) and hostile `uq` options; a journal of other inputs in the output directory; a resumed run; `check` agreeing with `uq` on the model's own inputs | uq.py |
| fmu | `fmu` export with hostile `--param` key paths and `--out` names (unwritable, no `.fmu`, a directory) | uq.py |
| calibrate_traces | `calibrate` over several generated traces, two cases in five valid calibrations that must exit 0, the others with one to three mutations: shared and per-trace `--fit` keys, priors (command line and file), `--profile`, `--residuals`, `--rated`, `--gearbox-kind`, `--segment`, `--holdout`, `--band-from` a calibration over several traces or a crafted one; written models checked and run | calibrate.py |
| python | bad arguments and DataFrames through the Python API, and through a process pool | pyapi.py, pyworker.py |

Each case runs in its own scratch directory under an 8 GiB address-space limit with a time
limit (10 s; more for studies, bench and the Python pool). The failure classes are listed in
scripts/hostile/core.py (and FAMILY_CLASSES below); the campaign prints the count of each, per
family, with the share of cases that reached a fit and the first examples, and exits 1 if any is
nonzero. Outside the test suite: not run by CI (it takes long
on 2 cores).
"""
import argparse
import collections
import json
import concurrent.futures as cf
import os
import random
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from hostile import calibrate, cli, core, pyapi, report, stdio, study, uq  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WEIGHTS = {"cli": 0.30, "set": 0.20, "study_spec": 0.08, "study_kill": 0.02, "study_two": 0.015,
           "study_huge": 0.005, "stdio": 0.10, "report": 0.12, "python": 0.16, "uq": 0.04, "fmu": 0.02,
           "calibrate_traces": 0.04}
SMALL_STUDY = """[study]
name = "small"
model = "{model}"
[job]
kind = "steady"
points = [{{gear = "1", speed_rpm = 1450.0, torque_nm = 50.0}}]
[[parameters]]
path = "lubrication.oil_level_mm"
values = [40.0, 50.0]
"""


class Context:
    """What every case needs: the binary, the interpreter, the templates of previous results."""

    def __init__(self, a, tmp):
        self.bin, self.python, self.limit, self.root = a.bin, a.python, a.limit, ROOT
        self.rig = os.path.join(ROOT, "tests", "data", "rig_short.csv")
        self.workers = []
        self.texts = cli.model_texts(ROOT)
        self.study_file = os.path.join(tmp, "small_study.toml")
        with open(self.study_file, "w") as f:
            f.write(SMALL_STUDY.format(model=os.path.join(ROOT, "models", "fzg_c.toml")))
        self.templates = make_templates(self, tmp)


def make_templates(ctx, tmp):
    """A complete previous result set of each writing command (copied into the output directory
    of the cases that start from one)."""
    fzg = os.path.join(ROOT, "models", "fzg_c.toml")
    t = {k: os.path.join(tmp, "tpl", k) for k in ("run", "map", "bench", "study", "validate", "rating")}
    cmds = {
        "run": ["run", fzg, "--cycle", ctx.rig, "--quiet", "--out", t["run"]],
        "map": ["map", fzg, "--gear", "1", "--speed-rpm", "1000:2000:2", "--torque-nm", "10:50:2", "--quiet",
                "--out", t["map"]],
        "bench": ["bench", fzg, "--cycle", ctx.rig, "--repeats", "1", "--min-rtol", "1e-4", "--solvers", "ros3",
                  "--out", t["bench"]],
        "study": ["study", ctx.study_file, "--quiet", "--out", t["study"]],
        "validate": ["validate", os.path.join(ROOT, "validation"), "--out", t["validate"]],
        "rating": ["rating", fzg, "--gear", "1", "--speed-rpm", "1000:2000:2", "--oil-limit-c", "90", "--quiet",
                   "--out", t["rating"]],
    }
    for k, args in cmds.items():
        p = subprocess.run([ctx.bin] + args, capture_output=True, cwd=tmp)
        if p.returncode != 0:
            sys.exit(f"template {k} failed: {p.stderr.decode(errors='replace')[-500:]}")
    return t


def make_case(i, seed, ctx, families):
    rng = random.Random(seed * 1_000_003 + i)
    names = list(families)
    fam = rng.choices(names, weights=[families[n] for n in names])[0]
    if fam in ("cli", "set"):
        return cli.make_case(i, rng, ctx.texts, fam)
    if fam.startswith("study"):
        return study.make_case(i, rng, ROOT, fam)
    if fam == "stdio":
        return stdio.make_case(i, rng)
    if fam == "report":
        return report.make_case(i, rng)
    if fam in ("uq", "fmu"):
        return uq.make_case(i, rng, ROOT, ctx.texts, fam)
    if fam == "calibrate_traces":
        return calibrate.make_case(i, rng)
    return pyapi.make_case(i, rng, ROOT, ctx.texts)


RUNNERS = {"cli": cli.run_case, "set": cli.run_case, "stdio": stdio.run_case, "report": report.run_case,
           "python": pyapi.run_case, "uq": uq.run_case, "fmu": uq.run_case,
           "calibrate_traces": calibrate.run_case}


def run_case(case, ctx):
    fam = case["family"]
    runner = study.run_case if fam.startswith("study") else RUNNERS[fam]
    try:
        return runner(case, ctx)
    except Exception as e:  # a harness error is reported, not hidden
        return {"id": case["id"], "family": fam, "cmd": case.get("label", ""), "classes": ["harness"],
                "detail": f"{type(e).__name__}: {e}"}


# Failure classes of one family (beside core.CLASSES): `later_refused`, a written calibrated
# model that `check` refuses; `valid_refused`, a valid calibration (no mutation) refused.
FAMILY_CLASSES = ["later_refused", "valid_refused"]


class Tally:
    def __init__(self):
        self.counts = collections.Counter()
        self.by_family = collections.defaultdict(collections.Counter)
        self.exits = collections.defaultdict(collections.Counter)
        self.examples = collections.defaultdict(list)
        self.fits = collections.Counter()
        self.valid = collections.Counter()
        self.done = 0
        self.log = None

    def add(self, r):
        self.done += 1
        fam = r["family"]
        self.by_family[fam]["cases"] += 1
        self.exits[fam][str(r.get("rc", "-"))] += 1
        self.fits[fam] += bool(r.get("fit"))
        self.valid[fam] += bool(r.get("valid"))
        for k in sorted(set(r["classes"])):
            self.counts[k] += 1
            self.by_family[fam][k] += 1
            if len(self.examples[k]) < 5:
                self.examples[k].append(r)

    def print(self, a, wall):
        print(f"cases run: {self.done} (seed {a.seed}, jobs {a.jobs}, {wall / 60:.1f} min wall)")
        print("| family | cases | exit codes / outcomes | reached a fit | failures |")
        print("|---|---|---|---|---|")
        for fam in sorted(self.by_family):
            c = self.by_family[fam]
            ex = ", ".join(f"{k}: {v}" for k, v in sorted(self.exits[fam].items()))
            fails = ", ".join(f"{k} {v}" for k, v in sorted(c.items()) if k != "cases") or "0"
            fit = f"{self.fits[fam]} ({100 * self.fits[fam] / c['cases']:.0f} %)" if self.fits[fam] else "-"
            print(f"| {fam} | {c['cases']} | {ex} | {fit} | {fails} |")
        for k in core.CLASSES + FAMILY_CLASSES + ["harness"]:
            print(f"{k:>19}: {self.counts.get(k, 0)}")
        for k, ex in self.examples.items():
            for r in ex[:3]:
                print(f"  e.g. {k}: case {r['id']} ({r['family']}) exit {r.get('rc')}: {r['cmd'][:300]} "
                      f"{str(r.get('detail', ''))[:400]}")


def stop(*_):
    raise KeyboardInterrupt


def python_ok(python):
    p = subprocess.run([python, "-c", "import geartherm, pandas, numpy"], capture_output=True)
    return p.returncode == 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=29)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "geartherm"))
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--families", default="all")
    ap.add_argument("--limit", type=float, default=core.LIMIT_S)
    ap.add_argument("--log", help="append each failing case (JSON, one per line) to this file as it happens")
    a = ap.parse_args()
    # A SIGTERM ends the campaign like Ctrl-C: the worker interpreters are stopped on the way out.
    signal.signal(signal.SIGTERM, stop)
    a.bin = os.path.abspath(a.bin)
    families = dict(WEIGHTS) if a.families == "all" else {f: WEIGHTS[f] for f in a.families.split(",")}
    if "python" in families and not python_ok(a.python):
        sys.exit(f"{a.python}: cannot import geartherm, pandas and numpy (install the wheel, or leave out "
                 "the python family with --families)")
    tally = Tally()
    start = time.time()
    with tempfile.TemporaryDirectory(prefix="hostile_campaign_") as tmp:
        ctx = Context(a, tmp)
        tally.log = open(a.log, "a") if a.log else None
        try:
            run_all(a, ctx, families, tally)
        finally:
            for w in ctx.workers:
                w.stop()
    tally.print(a, time.time() - start)
    sys.exit(1 if any(tally.counts.values()) else 0)


def run_all(a, ctx, families, tally):
    """Cases generated as they are submitted (at most 4 per thread in flight)."""
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        pending = set()
        for i in range(a.cases):
            pending.add(ex.submit(run_case, make_case(i, a.seed, ctx, families), ctx))
            if len(pending) >= 4 * a.jobs:
                done, pending = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
                for f in done:
                    record(tally, f.result())
        for f in cf.as_completed(pending):
            record(tally, f.result())


def record(tally, r):
    tally.add(r)
    if r["classes"] and tally.log:
        tally.log.write(json.dumps(r, default=str) + "\n")
        tally.log.flush()
    if tally.done % 1000 == 0:
        print(f"{tally.done} cases: {dict(tally.counts)}", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
