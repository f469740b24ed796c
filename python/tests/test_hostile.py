"""Hostile use of the Python API: errors through a process pool keep their class and key path,
bad arguments and DataFrames get clear errors, and a study on a Dask LocalCluster whose worker
is killed mid-study completes with every case exactly once, equal to the local run."""

import concurrent.futures as cf
import math
import os
import signal
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import geartherm

ROOT = Path(__file__).resolve().parents[2]
FZG = ROOT / "models" / "fzg_c.toml"


def _bad_override(path):
    geartherm.Model.load(path).override({"gears[0].x": "a"})


def _frozen_solve(path):
    geartherm.Model.load(path).run(cycle="wltc", frozen_viscosity_c=0.0, summary_only=True)


def _child_map(path):
    m = geartherm.Model.load(path).map(gear="1", speed_rpm=[1000.0, 2000.0], torque_nm=[10.0, 50.0])
    model = geartherm.Model.load(path)
    model.run(cycle=str(ROOT / "tests" / "data" / "rig_short.csv"), summary_only=True)
    model.steady(gear="1", speed_rpm=1500.0, torque_nm=50.0)
    return len(m)


@pytest.mark.parametrize("method", ["fork", "spawn", "forkserver"])
def test_parallel_jobs_run_in_a_pool_forked_after_a_parallel_call(method):
    # A forked child inherits rayon's pool without its threads: its first parallel call (a map,
    # a rating, a study) waited forever when the parent had made one before the fork.
    import multiprocessing as mp

    here = geartherm.Model.load(FZG).map(gear="1", speed_rpm=[1000.0, 3000.0], torque_nm=[10.0, 50.0])
    with cf.ProcessPoolExecutor(1, mp_context=mp.get_context(method)) as pool:
        assert pool.submit(_child_map, str(FZG)).result(timeout=60) == len(here) == 4
        r = pool.submit(_child_map, str(FZG)).result(timeout=60)
        assert r == 4


def _bad_frame_run(path):
    try:
        geartherm.Model.load(path).run(cycle=pd.DataFrame({"a": [0.0, 1.0]}))
    except geartherm.InputError as e:
        return str(e)


def test_a_dataframe_cycle_is_named_as_such_not_by_a_temporary_file():
    # The message named a temporary CSV (/tmp/geartherm-cycle-…/dataframe.csv), gone after the
    # call and different in every process.
    here = _bad_frame_run(str(FZG))
    assert here.startswith("cycle: DataFrame, line 1: column a: unknown column"), here
    with cf.ProcessPoolExecutor(1) as pool:
        assert pool.submit(_bad_frame_run, str(FZG)).result(timeout=60) == here


def test_errors_cross_a_process_pool_with_their_class_and_key_path():
    with pytest.raises(geartherm.ModelError) as here:
        _bad_override(str(FZG))
    with cf.ProcessPoolExecutor(max_workers=1) as pool:
        with pytest.raises(geartherm.ModelError) as there:
            pool.submit(_bad_override, str(FZG)).result()
        assert str(there.value) == str(here.value)
        assert there.value.path == "gears[0].x" == here.value.path
        assert there.value.problems == here.value.problems
        with pytest.raises(geartherm.SolveError, match="outside"):
            pool.submit(_frozen_solve, str(ROOT / "models" / "at6_lepelletier.toml")).result()


def test_bad_arguments_and_dataframes_get_clear_errors():
    m = geartherm.Model.load(FZG)
    for bad in (None, [("lubrication.oil_level_mm", 50)], "x"):
        with pytest.raises(TypeError, match="mapping of key path"):
            m.override(bad)
    frame = pd.DataFrame({"path": ["lubrication.oil_level_mm"], "values": [[40.0, 50.0]]})
    job = {"kind": "steady", "points": [{"gear": "1", "speed_rpm": 1450.0, "torque_nm": 50.0}]}
    for bad in (frame, frame["path"], ["lubrication.oil_level_mm"], {"lubrication.oil_level_mm": frame}):
        with pytest.raises(TypeError, match="parameters must be a mapping"):
            geartherm.study(m, bad, job)
    params = {"lubrication.oil_level_mm": {"values": [40.0, 50.0]}}
    with pytest.raises(geartherm.InputError, match="more than once"):
        geartherm.study(m, params, job, cases=[0, 0])
    for i in (-1, 2, 10**20):
        with pytest.raises(geartherm.InputError, match=r"must lie in \[0, 2\)"):
            geartherm.study(m, params, job, cases=[i])
    with pytest.raises(TypeError):
        geartherm.study(m, params, job, cases=[0.5])
    # A million threads would each be started before the first case runs.
    for n in (0, 1025, 10**6):
        with pytest.raises(geartherm.InputError, match=r"threads_per_task .* must lie in \[1, 1024\]"):
            geartherm.study(m, params, job, threads_per_task=n)
    with pytest.raises(geartherm.InputError, match=r"oil_temp_c .* must lie in \[-35, 200\]"):
        m.losses(gear="1", speed_rpm=1450.0, torque_nm=50.0, oil_temp_c=-60.0)


def _long_rig_cycle(path, rows):
    lines = ["time_s,input_speed_rpm,input_torque_nm,gear"]
    lines += [f"{k},{3000 if k % 2 else 1000},{50 + 25 * (k % 3)},1" for k in range(rows)]
    path.write_text("\n".join(lines) + "\n")


def test_a_study_survives_a_killed_dask_worker_with_every_case_once(tmp_path):
    import distributed as distributed
    cycle = tmp_path / "long.csv"
    _long_rig_cycle(cycle, 60_000)  # about 0.2 s per case
    params = {"lubrication.oil_level_mm": {"range": [40.0, 60.0]}, "thermal.initial_temp_c": {"range": [20.0, 40.0]}}
    job = {"kind": "run", "cycles": [str(cycle)], "options": {"summary_only": True}}
    plan = {"plan": "lhs", "cases": 16, "seed": 3}
    local = geartherm.study(FZG, params, job, plan)
    assert len(local) == 16 and (local.status == "ok").all()
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        pids = client.run(os.getpid)
        result, error = {}, {}

        def go():
            try:
                result["df"] = geartherm.study(FZG, params, job, plan, client=client, batch_size=1, threads_per_task=1)
            except BaseException as e:  # reported below
                error["e"] = e

        t = threading.Thread(target=go)
        t.start()
        killed = None
        deadline = time.time() + 60
        while killed is None and time.time() < deadline and t.is_alive():
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed = busy[0]
            else:
                time.sleep(0.01)
        assert killed is not None, "no worker was seen busy"
        assert t.is_alive(), "the study ended before the worker was killed"
        t.join(300)
        assert not t.is_alive(), "the study did not finish after the kill"
        assert not error, f"the study failed after a worker was killed: {error.get('e')!r}"
        assert pids[killed] not in client.run(os.getpid).values(), "the killed worker's process still runs"
    dd = result["df"]
    assert list(dd.case) == list(local.case), "every case exactly once, in case order"
    assert not dd.case.duplicated().any()
    pd.testing.assert_frame_equal(dd, local, check_exact=True)
    for col in local.columns:
        for x, y in zip(local[col].tolist(), dd[col].tolist()):
            assert (x == y) or (isinstance(x, float) and math.isnan(x) and math.isnan(y)), col
