"""One pipeline: every row of tests/data/option_limits.toml (inputs at and beyond every job
option's limits) is accepted or refused alike, with the same message, by the Python API and by
the CLI (tests/drift.rs holds the CLI against a study case)."""

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import geartherm

ROOT = Path(__file__).resolve().parents[2]
MODEL = "models/fzg_c.toml"
# The `geartherm` console script pip installed beside this interpreter (GEARTHERM_BIN: another).
BIN = Path(os.environ.get("GEARTHERM_BIN", Path(sys.executable).parent / "geartherm"))


def _rows():
    doc = tomllib.loads((ROOT / "tests" / "data" / "option_limits.toml").read_text())
    for k, r in enumerate(doc["row"]):
        options = dict(doc["base"][r["job"]], **r["set"])
        if r["job"] == "run":
            options["summary_only"] = True
        yield k, r["job"], options, r["expect"]


def _cli(job, options, out):
    args = [str(BIN), job, MODEL]
    for k, v in options.items():
        flag = "--" + k.replace("_", "-")
        if v is True:
            args.append(flag)
        elif isinstance(v, list):
            args.append(f"{flag}={','.join(repr(x) for x in v)}")
        elif v is not False:
            args.append(f"{flag}={v!r}" if isinstance(v, float) else f"{flag}={v}")
    if job in ("run", "rating"):
        args += ["--quiet", "--out", str(out)]
    p = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    kind = {0: "ok", 1: "refused", 2: "failed"}[p.returncode]
    return kind, "" if kind == "ok" else _unspelled(p.stderr.strip(), options)


def _unspelled(msg, options):
    """A CLI message as the job layer wrote it: the CLI adds the flag after an option named at
    the message's start (``speed_rpm (--speed-rpm) = …``), Python names the keyword only."""
    for k in list(options) + ["gear", "solver", "solvers"]:
        spelled = f"{k} (--{k.replace('_', '-')})"
        if msg.startswith(spelled):
            return k + msg[len(spelled):]
    return msg


def _python(model, job, options):
    o = dict(options)
    try:
        if job == "losses":
            model.losses(o.pop("gear"), o.pop("speed_rpm"), o.pop("torque_nm"), o.pop("oil_temp_c"))
        elif job == "steady":
            model.steady(**o)
        elif job == "rating":
            model.rating(**o)
        else:
            model.run(**o)
    except geartherm.SolveError as e:
        return "failed", str(e)
    except (geartherm.InputError, geartherm.ModelError) as e:
        return "refused", str(e)
    return "ok", ""


def test_python_and_cli_accept_and_refuse_alike(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    model = geartherm.Model.load(MODEL)
    seen = {"refused": 0, "accepted": 0}
    for k, job, options, expect in _rows():
        cli = _cli(job, options, tmp_path / f"r{k}")
        py = _python(model, job, options)
        assert py == cli, f"row {k}: {job} {options}"
        assert (cli[0] == "refused") == (expect == "reject"), f"row {k}: {job} {options}: {cli}"
        seen["refused" if cli[0] == "refused" else "accepted"] += 1
    assert seen["refused"] > 20 and seen["accepted"] > 15


# Case selection: every shard and case-list form is accepted or refused alike, with the same
# message, by the CLI (`study --list --shard/--cases`), Python (`Study.run`) and the Dask path
# (`Study.run(client=...)`); tests/drift.rs holds the CLI against the study layer for the text
# forms too.
SELECTION_STUDY = "tests/data/selection_study.toml"
SHARDS = [(0, 2), (1, 2), (3, 4), (0, 1), (2, 2), (3, 2), (0, 0), (-1, 2), (1, -2)]
CASE_LISTS = [[0], [3, 0], [0, 1, 2, 3], [4], [-1], [1, 1], [], [2, -3]]


def _cli_select(cases, shard):
    args = [str(BIN), "study", SELECTION_STUDY, "--list"]
    if cases is not None:
        args.append("--cases=" + ",".join(str(i) for i in cases))
    if shard is not None:
        args.append(f"--shard={shard[0]}/{shard[1]}")
    p = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    if p.returncode == 0:
        return "ok", sorted(line.split("\t")[0] for line in p.stdout.splitlines())
    assert p.returncode == 1, p.stderr
    return "refused", _unspelled(p.stderr.strip(), ["shard", "cases"])


def _py_select(study, cases, shard, client=None):
    try:
        df = study.run(cases=cases, shard=shard, client=client, progress=False, threads=1 if client is None else None)
    except geartherm.InputError as e:
        return "refused", str(e)
    return "ok", sorted(df.case)


def test_case_selection_is_accepted_and_refused_alike_by_the_cli_python_and_dask(monkeypatch):
    import distributed

    monkeypatch.chdir(ROOT)
    study = geartherm.Study.load(SELECTION_STUDY)
    forms = [(None, s) for s in SHARDS] + [(c, None) for c in CASE_LISTS] + [([0], (0, 2))]
    seen = {"ok": 0, "refused": 0}
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        for cases, shard in forms:
            cli = _cli_select(cases, shard)
            assert _py_select(study, cases, shard) == cli, (cases, shard)
            assert _py_select(study, cases, shard, client) == cli, (cases, shard)
            seen[cli[0]] += 1
    assert seen["ok"] >= 6 and seen["refused"] >= 10, seen


def test_a_dask_study_into_a_directory_equals_the_local_one_bit_for_bit(tmp_path, monkeypatch):
    """The Dask path goes through the runner: the same journal, resume and compaction."""
    import distributed

    monkeypatch.chdir(ROOT)
    study = geartherm.Study.load(SELECTION_STUDY)
    local = study.run(out=tmp_path / "local", progress=False)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        # Half by shards, the rest resumed: journal.shard-0-of-2 is read back, not solved again.
        part = study.run(out=tmp_path / "dask", shard=(0, 2), client=client, progress=False, batch_size=1)
        assert sorted(part.case) == ["000000-p0000", "000002-p0000"]
        assert (tmp_path / "dask" / "journal.shard-0-of-2.jsonl").is_file()
        dd = study.run(out=tmp_path / "dask", client=client, progress=False, batch_size=1)
        assert study.tally["already_done"] == 2 and study.tally["solved"] == 2
    import pandas as pd

    pd.testing.assert_frame_equal(dd, local, check_exact=True)
    assert (tmp_path / "dask" / "study.csv").read_bytes() == (tmp_path / "local" / "study.csv").read_bytes()
    assert (tmp_path / "dask" / "study.parquet").is_file()
