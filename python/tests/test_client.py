"""Python as a first-class client: the shared study runner (Ctrl-C, resume, the CLI's files),
errors that travel, discoverability, one output schema, and the round trip of results."""

import errno
import json
import multiprocessing
import os
import pickle
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pandas as pd
import pytest

import geartherm

ROOT = Path(__file__).resolve().parents[2]
AT6 = ROOT / "models" / "at6_lepelletier.toml"
FZG = ROOT / "models" / "fzg_c.toml"
# The `geartherm` console script pip installed beside this interpreter (GEARTHERM_BIN: another).
BIN = Path(os.environ.get("GEARTHERM_BIN", Path(sys.executable).parent / "geartherm"))
BAD = {'thermal.coolers["atf_cooler"].effectiveness': 1.4}


def _study_toml(tmp_path, cases=12, cycle="hwfet", name="t"):
    f = tmp_path / f"{name}.toml"
    f.write_text(
        f"""
[study]
name = "{name}"
model = "{AT6}"
[job]
kind = "run"
cycles = ["{cycle}"]
[sampling]
plan = "lhs"
cases = {cases}
seed = 5
[[parameters]]
path = "lubrication.oil_level_mm"
range = [40.0, 80.0]
[[parameters]]
path = "oil.catalogue"
values = ["dexron_vi_atf", "fva_3a"]
"""
    )
    return f


# ---------------------------------------------------------------------------------------------
# 1. One study runner


def test_a_study_file_with_out_writes_what_the_cli_writes(tmp_path):
    toml = _study_toml(tmp_path)
    cli = tmp_path / "cli"
    subprocess.run([str(BIN), "study", str(toml), "--out", str(cli), "--quiet"], check=True, capture_output=True)
    py = tmp_path / "py"
    df = geartherm.study(toml, out=py, progress=False)
    names = lambda d: sorted(p.name for p in d.iterdir() if not p.name.startswith("."))
    assert names(py) == names(cli) == ["journal.jsonl", "main_effects.png", "pareto.png", "study.csv", "study.parquet"]
    assert (py / "study.csv").read_bytes() == (cli / "study.csv").read_bytes()
    assert (py / "study.parquet").read_bytes() == (cli / "study.parquet").read_bytes()
    back = geartherm.read_study(py)
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    pq = pd.read_parquet(py / "study.parquet")
    assert list(pq.columns) == list(df.columns)
    assert pq["energy_total_j"].tolist() == df["energy_total_j"].tolist()
    # A study object gives the same rows, in memory.
    s = geartherm.Study.load(toml)
    pd.testing.assert_frame_equal(s.run(progress=False), df, check_exact=True)


def test_progress_is_reported_and_a_callback_exception_stops_the_study(tmp_path):
    toml = _study_toml(tmp_path, cases=6)
    seen = []
    geartherm.study(toml, progress=lambda d, n: seen.append((d, n)), threads=1)
    assert seen[-1] == (6, 6) and all(n == 6 for _, n in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)

    class Stop(Exception):
        pass

    def stop(d, n):
        if d >= 1:
            raise Stop()

    out = tmp_path / "stopped"
    slow = _study_toml(tmp_path, cases=300, cycle="wltc", name="slow")
    with pytest.raises(Stop):
        geartherm.study(slow, out=out, progress=stop, threads=1)
    journaled = (out / "journal.jsonl").read_text().splitlines()[1:]
    assert 1 <= len(journaled) < 300


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


CHILD = """
import sys, geartherm
geartherm.study(sys.argv[1], out=sys.argv[2], progress=False, threads=1)
"""


def test_ctrl_c_stops_a_study_cleanly_and_the_rerun_solves_every_case_once(tmp_path):
    toml = _study_toml(tmp_path, cases=600, cycle="wltc")
    out = tmp_path / "out"
    # SIGINT as a foreground process gets it (a shell without job control starts background
    # commands with SIGINT ignored, and Python then installs no handler of its own).
    p = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(toml), str(out)], stderr=subprocess.PIPE, text=True, preexec_fn=_default_sigint
    )
    journal = out / "journal.jsonl"
    deadline = time.time() + 120
    while time.time() < deadline:
        if journal.exists() and len(journal.read_text().splitlines()) >= 3:
            break
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    first = [json.loads(l)["case"] for l in journal.read_text().splitlines()[1:]]
    assert p.returncode != 0 and "KeyboardInterrupt" in err, (p.returncode, len(first), err)
    assert 2 <= len(first) < 600, len(first)
    assert not (out / "study.csv").exists()
    s = geartherm.Study.load(toml)
    df = s.run(out=out, progress=False)
    assert s.tally["already_done"] == len(first) and s.tally["solved"] == 600 - len(first), (s.tally, len(first))
    every = [json.loads(l)["case"] for l in journal.read_text().splitlines()[1:]]
    assert sorted(every) == sorted(set(every)) == sorted(s.cases)
    assert list(df.case) == s.cases


def test_the_cli_stops_on_sigint_with_status_130_and_resumes(tmp_path):
    toml = _study_toml(tmp_path, cases=300, cycle="wltc")
    out = tmp_path / "out"
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    p = subprocess.Popen(
        [str(BIN), "study", str(toml), "--out", str(out), "--quiet"],
        env=env,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
    )
    journal = out / "journal.jsonl"
    deadline = time.time() + 120
    while time.time() < deadline:
        if journal.exists() and len(journal.read_text().splitlines()) >= 3:
            break
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert "resume" in err
    first = len(journal.read_text().splitlines()) - 1
    r = subprocess.run([str(BIN), "study", str(toml), "--out", str(out), "--quiet"], capture_output=True, text=True, check=True)
    assert f"{300 - first} cases solved" in r.stdout and f"{first} already done" in r.stdout, r.stdout
    every = [json.loads(l)["case"] for l in journal.read_text().splitlines()[1:]]
    assert len(every) == len(set(every)) == 300


# ---------------------------------------------------------------------------------------------
# 2. Errors that travel


def _bad_override(_):
    geartherm.Model.load(AT6).override(BAD)


@pytest.mark.parametrize("method", ["fork", "spawn", "forkserver"])
def test_a_model_error_crosses_a_process_pool_with_its_key_path(method):
    ctx = multiprocessing.get_context(method)
    with ctx.Pool(1) as pool:
        with pytest.raises(geartherm.ModelError) as e:
            pool.map(_bad_override, [0])
    assert e.value.path == "thermal.coolers[0].effectiveness"
    assert e.value.value and e.value.allowed and e.value.problems
    assert isinstance(e.value, ValueError)


def test_a_model_error_crosses_a_dask_cluster_with_its_key_path():
    import distributed as distributed
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as c, distributed.Client(c) as client:
        f = client.submit(_bad_override, 0)
        with pytest.raises(geartherm.ModelError) as e:
            f.result()
    assert e.value.path == "thermal.coolers[0].effectiveness"


def test_a_model_error_crosses_a_ray_task_with_its_key_path():
    import ray as ray
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False, ignore_reinit_error=True)
    try:
        # A lambda travels by value (this test module is not importable on Ray's workers).
        task = ray.remote(lambda path, bad: geartherm.Model.load(path).override(bad))
        # Ray re-raises a task's exception as a class deriving from both RayTaskError and the
        # task's own class, the original (unpickled) object in `.cause`.
        with pytest.raises(geartherm.ModelError) as e:
            ray.get(task.remote(str(AT6), BAD), timeout=120)
        cause = getattr(e.value, "cause", e.value)
        assert isinstance(cause, geartherm.ModelError)
        assert cause.path == "thermal.coolers[0].effectiveness"
        assert cause.value and cause.allowed and cause.problems
    finally:
        ray.shutdown()


def test_exceptions_pickle_with_their_fields_and_are_python_types(tmp_path):
    with pytest.raises(geartherm.ModelError) as e:
        geartherm.Model.load(AT6).override(BAD)
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is geartherm.ModelError
    assert (back.path, back.value, back.allowed, back.problems, str(back)) == (
        e.value.path,
        e.value.value,
        e.value.allowed,
        e.value.problems,
        str(e.value),
    )
    with pytest.raises(FileNotFoundError) as nf:
        geartherm.Model.load(tmp_path / "missing.toml")
    assert nf.value.errno == errno.ENOENT and nf.value.filename == str(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError):
        geartherm.Study.load(tmp_path / "missing_study.toml")
    with pytest.raises(geartherm.InputError) as ie:
        geartherm.Model.load(AT6).run(cycle="hwfet", rtol=5.0)
    assert isinstance(ie.value, ValueError) and ie.value.path == "rtol"
    assert issubclass(geartherm.SolveError, RuntimeError)


# ---------------------------------------------------------------------------------------------
# 3. Discoverable


def test_oils_and_cycles_are_listed():
    o = geartherm.oils()
    assert {"fva_3a", "dexron_vi_atf"} <= set(o.key)
    assert (o.nu40_cst > o.nu100_cst).all()
    c = geartherm.cycles()
    assert "wltc" in set(c.name)
    w = c.set_index("name").loc["wltc"]
    assert w.duration_s == 1800 and 23.0 < w.distance_km < 23.5


def test_every_public_name_has_a_numpy_style_docstring():
    import inspect

    for name in geartherm.__all__:
        obj = getattr(geartherm, name)
        if isinstance(obj, tuple):
            continue
        doc = inspect.getdoc(obj) or ""
        assert len(doc.splitlines()) >= 2, name
    for meth in ("load", "override", "losses", "steady", "map", "run"):
        doc = inspect.getdoc(getattr(geartherm.Model, meth))
        assert "Raises" in doc or "Returns" in doc, meth
    run = inspect.getdoc(geartherm.Model.run)
    assert "tr-bdf2" in run and "1e-4" in run and "1e-6" in run
    pkg = Path(geartherm.__file__).parent
    assert (pkg / "py.typed").exists() and (pkg / "_native.pyi").exists()


def test_html_reprs_and_range_warnings_as_python_warnings():
    at6 = geartherm.Model.load(AT6)
    assert "<table>" in at6._repr_html_() and at6.name in at6._repr_html_()
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = at6.run(cycle="hwfet", summary_only=True)
    assert "<table>" in r._repr_html_()
    ranged = [x for x in w if issubclass(x.category, geartherm.RangeWarning)]
    # One warning per result, on one line, however many entries the summary lists.
    assert len(ranged) == 1 and len(r.summary["warnings"]) > 1
    text = str(ranged[0].message)
    assert "\n" not in text and text.startswith(f"{len(r.summary['warnings'])} range warning(s)")
    assert all(w["item"] in text for w in r.summary["warnings"])


# ---------------------------------------------------------------------------------------------
# 4. One output schema


def test_the_column_set_and_dtypes_do_not_depend_on_the_overrides():
    at6 = geartherm.Model.load(AT6)
    a = at6.override({"lubrication.oil_level_mm": 60}).run(cycle="hwfet").timeseries
    b = at6.override({"lubrication.oil_level_mm": 40}).run(cycle="hwfet").timeseries
    assert set(a.columns) == set(b.columns)
    assert (a.dtypes.sort_index() == b.dtypes.sort_index()).all()
    assert a["gear"].map(type).eq(str).all()
    for src in geartherm.SOURCES:
        assert a[f"loss_{src}_w"].dtype == "float64"
    m = geartherm.Model.load(FZG).map(gear="1", speed_rpm=[1000, 2000], torque_nm=[50, 150])
    zeros = [c for c in m.columns if c.startswith("loss_") and m[c].eq(0).all()]
    assert zeros and all(m[c].dtype == "float64" for c in zeros)
    assert m["converged"].all() and m["iterations"].dtype == "Int64"


def test_per_source_names_are_one_rule_across_jobs():
    at6 = geartherm.Model.load(AT6)
    keys = [f"loss_{s}_w" for s in geartherm.SOURCES] + ["loss_total_w"]
    lo = at6.losses("3", 2500, 150, 80, output="dict")
    st = at6.steady(gear="6", speed_rpm=2000, torque_nm=100, output="dict")
    ts = at6.run(cycle="hwfet").timeseries
    mp = at6.map(gear="6", speed_rpm=[2000], torque_nm=[100])
    ra = geartherm.Model.load(FZG).rating(gear="1", speed_rpm=1500, oil_limit_c=90, output="dict")["points"][0]
    for where in (lo, st, ts.columns, mp.columns, ra["equilibrium"]):
        assert all(k in where for k in keys), keys
    assert ra["loss_total_w"] == ra["equilibrium"]["loss_total_w"]
    assert lo["loss_total_w"] == pytest.approx(sum(lo[k] for k in keys[:-1]))
    assert st["loss_total_w"] == pytest.approx(mp["loss_total_w"].iloc[0], rel=1e-9)
    # The study table: energy_<source>_j for runs, loss_<source>_w for steady points; the same
    # columns whatever the rows hold (here every case invalid).
    df = geartherm.study(AT6, {'thermal.coolers["atf_cooler"].effectiveness': {"values": [1.5, 2.0]}}, {"kind": "steady", "points": [{"gear": "6", "speed_rpm": 2000, "torque_nm": 100}]}, progress=False)
    assert set(df.status) == {"invalid"}
    assert all(k in df.columns for k in keys)
    assert df["loss_total_w"].dtype == "float64"


# ---------------------------------------------------------------------------------------------
# 5. Round trip


def test_read_run_equals_the_run_that_wrote_it(tmp_path):
    at6 = geartherm.Model.load(AT6)
    r = at6.run(cycle="hwfet")
    assert geartherm.read_run(r.write(tmp_path / "py")) == r
    cli = tmp_path / "cli"
    subprocess.run([str(BIN), "run", str(AT6), "--cycle", "hwfet", "--out", str(cli)], check=True, capture_output=True)
    back = geartherm.read_run(cli)
    assert back == r
    pd.testing.assert_frame_equal(back.timeseries, r.timeseries, check_exact=True)


def test_read_run_reads_directories_of_earlier_versions_with_todays_keys():
    # tests/fixtures/README.md: a run directory of 9d79de0 reads back as written; one of d379aa5
    # (mean_efficiency, per-source columns churning_w … total_loss_w) with today's keys.
    fx = ROOT / "tests" / "fixtures"
    now = geartherm.read_run(fx / "run_main_9d79de0")
    assert now.summary == json.loads((fx / "run_main_9d79de0" / "summary.json").read_text())
    old_file = json.loads((fx / "run_d379aa5" / "summary.json").read_text())
    old = geartherm.read_run(fx / "run_d379aa5")
    assert "mean_efficiency" not in old.summary
    assert old.summary["cycle_efficiency"] == old_file["mean_efficiency"]
    assert old.summary["energy_efficiency"] is None and old.summary["warnings"] == []
    assert old.summary["energy_lost_j"]["churning"] == old_file["energy_lost_j"]["churning"]
    assert old.summary["energy_lost_j"]["bearing"] == 0.0
    assert list(old.timeseries["churning_w"]) == list(pd.read_csv(fx / "run_d379aa5" / "timeseries.csv")["churning_w"])
    with pytest.raises(FileNotFoundError):
        geartherm.read_run(fx / "no_such_run")


def test_a_cycle_as_a_dataframe_runs_like_its_file():
    at6 = geartherm.Model.load(AT6)
    df = pd.read_csv(ROOT / "models" / "cycles" / "hwfet.csv")
    a = at6.run(cycle=df, summary_only=True).summary
    b = at6.run(cycle="hwfet", summary_only=True).summary
    assert a["energy_lost_j"] == b["energy_lost_j"]
    assert a["temperatures_c"] == b["temperatures_c"]


def test_plots_and_polars(tmp_path):
    import matplotlib  # noqa: F401 (the extra the test needs)
    at6 = geartherm.Model.load(AT6)
    r = at6.run(cycle="hwfet")
    fig = r.plot()
    assert len(fig.axes) == 3
    fig.savefig(tmp_path / "run.png")
    df = geartherm.study(_study_toml(tmp_path, cases=8), progress=False)
    from geartherm import plots

    f = plots.pareto(df, "energy_total_j", "temp_max_sump_c", color_by="oil.catalogue")
    labels = [t.get_text() for t in f.axes[0].texts]
    assert labels and set(labels) <= set(df.case)
    assert f.axes[0].get_xlabel().endswith(("[kJ]", "[MJ]")) and f.axes[0].get_ylabel().endswith("[°C]")
    import polars as pl
    p = r.to_polars()
    assert isinstance(p, pl.DataFrame) and p.columns == list(r.timeseries.columns)
