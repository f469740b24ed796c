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
    return kind, "" if kind == "ok" else p.stderr.strip()


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
