"""One pipeline: every row of tests/data/option_limits.toml (inputs at and beyond every job
option's limits, calibrate's among them) is accepted or refused alike, with the same message, by
the Python API and by the CLI (tests/drift.rs holds the CLI against a study case and the job
layer)."""

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


def _outcome(call):
    """("ok", ""), ("failed", message) or ("refused", message) of ``call()``."""
    try:
        call()
    except geartherm.SolveError as e:
        return "failed", str(e)
    except (geartherm.InputError, geartherm.ModelError) as e:
        return "refused", str(e)
    return "ok", ""


def _python(model, job, options):
    o = dict(options)
    if job == "losses":
        return _outcome(lambda: model.losses(o.pop("gear"), o.pop("speed_rpm"), o.pop("torque_nm"), o.pop("oil_temp_c")))
    method = {"steady": model.steady, "rating": model.rating}.get(job, model.run)
    return _outcome(lambda: method(**o))


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


# Calibrate's rows (`[[calibrate_row]]`): `Model.calibrate` against `geartherm calibrate`.
# Studies do not calibrate, so no study front end applies.
CALIBRATE_NAMES = ["fit", "holdout", "rtol", "atol", "max_steps", "max_iterations", "segment", "residuals", "prior",
                   "profile", "gearbox_kind", "rated", "trace", "band_quantile"]


def _calibrate_rows():
    doc = tomllib.loads((ROOT / "tests" / "data" / "option_limits.toml").read_text())
    base = dict(doc["base"]["calibrate"])
    model = base.pop("model")
    for k, r in enumerate(doc["calibrate_row"]):
        yield k, model, dict(base, **r["set"]), r["expect"]


def _calibrate_cli(model, options, out):
    """Each list item a flag of its own; ``segments`` is the ``--segment`` flag."""
    args = [str(BIN), "calibrate", model]
    for k, v in options.items():
        flag = "--" + ("segment" if k == "segments" else k).replace("_", "-")
        args += [f"{flag}={x}" for x in (v if isinstance(v, list) else [v])]
    p = subprocess.run(args + ["--out", str(out)], cwd=ROOT, capture_output=True, text=True)
    kind = {0: "ok", 1: "refused", 2: "failed"}[p.returncode]
    return kind, "" if kind == "ok" else _unspelled(p.stderr.strip(), CALIBRATE_NAMES)


def _calibrate_python(model, options):
    """``Model.calibrate`` with the row's options (``rated``: a pair of floats)."""
    o = dict(options)
    trace = o.pop("trace")
    if "rated" in o:
        o["rated"] = tuple(float(x) for x in o["rated"].split(":"))
    return _outcome(lambda: model.calibrate(trace, **o))


def test_calibrate_from_python_and_the_cli_accepts_and_refuses_alike(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    seen = {"refused": 0, "accepted": 0}
    models = {}
    for k, path, options, expect in _calibrate_rows():
        model = models.setdefault(path, geartherm.Model.load(path))
        cli = _calibrate_cli(path, options, tmp_path / f"c{k}")
        py = _calibrate_python(model, options)
        assert py == cli, f"calibrate row {k}: {options}"
        assert (cli[0] == "refused") == (expect == "reject"), f"calibrate row {k}: {options}: {cli}"
        seen["refused" if cli[0] == "refused" else "accepted"] += 1
    assert seen["refused"] >= 30 and seen["accepted"] >= 15, seen


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


# `uq`: the model file's own `[uncertainty]` and the options, valid and not, accepted or
# refused alike with the same message by the CLI and `Model.uq` (tests/drift.rs holds the CLI
# against the use case with the same rows).
AMB = 'thermal.boundaries["ambient"].temp_c'
LINK = 'thermal.links["oil-air"].conductance_w_per_k'
UQ_ROWS = [
    ((AMB, "normal", 20.0, 2.0), {}),
    ((AMB, "normal", 20.0, -1.0), {}),
    ((LINK, "uniform", 4.0, 2.0), {}),
    ((LINK, "uniform", 2.0, 4.0), {}),
    ((LINK, "normal", 3.0, 2.0), {}),
    ((AMB, "lognormal", 20.0, 0.1), {}),
    (('thermal.links["nope"].conductance_w_per_k', "uniform", 2.0, 4.0), {}),
    ((AMB, "normal", 20.0, 2.0), {"samples": 0}),
    ((AMB, "normal", 20.0, 2.0), {"samples": 1000001}),
    ((AMB, "normal", 20.0, 2.0), {"samples": 1000000, "sobol": True}),
    ((AMB, "normal", 20.0, 2.0), {"limits": {"nope": 100.0}}),
    ((AMB, "normal", 20.0, 2.0), {"limits": {"oil": 25.0}}),
    ((AMB, "normal", 20.0, 2.0), {"percentiles": [95.0, 5.0]}),
    ((AMB, "normal", 20.0, 2.0), {"confidence": 1.0}),
    ((AMB, "normal", 20.0, 2.0), {"bootstrap": 10001}),
    ((AMB, "normal", 20.0, 2.0), {"series_points": 1}),
    ((AMB, "normal", 20.0, 2.0), {"sobol": True}),
]
KEYS = {"normal": ("mean", "sd"), "lognormal": ("median", "sigma_ln"), "uniform": ("lo", "hi")}


def _uq_model_text(path, dist, a, b):
    pt6 = (ROOT / "models" / "pt6_spur_pair.toml").read_text()
    head = pt6[: pt6.index("\n[thermal]")]
    k = KEYS[dist]
    return (
        f'{head}\n[thermal]\noil_node = "oil"\ninitial_temp_c = 10.0\n\n[[thermal.nodes]]\nname = "oil"\n'
        'capacity_j_per_k = 2000.0\n\n[[thermal.boundaries]]\nname = "ambient"\ntemp_c = 20.0\n\n'
        '[[thermal.boundaries]]\nname = "coolant"\ntemp_c = 60.0\n\n[[thermal.links]]\nname = "oil-air"\n'
        'between = ["oil", "ambient"]\nconductance_w_per_k = 3.0\n\n[[thermal.links]]\nname = "oil-coolant"\n'
        'between = ["oil", "coolant"]\nconductance_w_per_k = 1.0\n\n'
        f"[[uncertainty.inputs]]\npath = '{path}'\ndist = \"{dist}\"\n{k[0]} = {a!r}\n{k[1]} = {b!r}\n"
    )


def _uq_cli(model, cycle, options, out):
    args = [str(BIN), "uq", str(model), "--cycle", str(cycle), "--quiet", "--out", str(out)]
    args.append(f"--samples={options.get('samples', 8)}")
    for k, v in options.items():
        if k == "sobol":
            args.append("--sobol")
        elif k == "limits":
            args += [f"--limit={n}={t!r}" for n, t in v.items()]
        elif k == "percentiles":
            args.append("--percentiles=" + ",".join(repr(x) for x in v))
        elif k != "samples":
            args.append(f"--{k.replace('_', '-')}={v!r}")
    p = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    kind = {0: "ok", 1: "refused"}[p.returncode]
    names = ["samples", "limit", "percentiles", "confidence", "bootstrap", "series_points"]
    return kind, "" if kind == "ok" else _unspelled(p.stderr.strip(), names)


def _uq_python(model, text, cycle, options):
    o = dict(options)
    o.setdefault("samples", 8)
    try:
        geartherm.Model.from_text(text, str(model)).uq(str(cycle), threads=1, **o)
    except (geartherm.InputError, geartherm.ModelError) as e:
        return "refused", str(e)
    return "ok", ""


def test_uq_is_accepted_and_refused_alike_by_the_cli_and_python(tmp_path):
    cycle = tmp_path / "standstill.csv"
    cycle.write_text("time_s,input_speed_rpm,input_torque_nm,gear\n" + "".join(f"{k * 50},0,0,1\n" for k in range(21)))
    seen = {"ok": 0, "refused": 0}
    for k, (inputs, options) in enumerate(UQ_ROWS):
        model = tmp_path / f"m{k}.toml"
        text = _uq_model_text(*inputs)
        model.write_text(text)
        cli = _uq_cli(model, cycle, options, tmp_path / f"o{k}")
        assert _uq_python(model, text, cycle, options) == cli, f"row {k}: {inputs} {options}"
        seen[cli[0]] += 1
    assert seen["ok"] >= 4 and seen["refused"] >= 12, seen
