"""Several traces in one fit from Python: DataFrames in, errors per trace and bands out; with a
Dask client (LocalCluster) the segments are integrated on the workers and the fit equals the
local one."""
import math

import pytest

import geartherm

MODEL = "models/helical_stage.toml"
H = 'thermal.links["oil-housing"].h_w_per_m2k'
M = 'thermal.nodes["housing"].mass_kg'


def _trace(model, mass, t0_gap=90_000.0):
    """Two segments (a gap of a day): steps and the steps reversed, simulated with `mass`."""
    import pandas as pd

    steps = [(3000.0, 200.0), (1500.0, 100.0), (4000.0, 250.0), (500.0, 50.0)]
    frames = []
    for seg, order in enumerate((steps, steps[::-1])):
        rows = [order[min(k // 15, 3)] for k in range(61)]
        cycle = pd.DataFrame(
            {
                "time_s": [k * 60.0 for k in range(61)],
                "input_speed_rpm": [r[0] for r in rows],
                "input_torque_nm": [r[1] for r in rows],
                "gear": ["1"] * 61,
                "boundary:ambient": [20.0] * 61,
                "node:oil": [30.0] * 61,
                "node:housing": [30.0] * 61,
            }
        )
        truth = model.override({H: 400.0, M: mass, "thermal.initial_temp_c": 30.0}).calibrate(
            cycle, holdout=["0:1e9"], initial_from_trace=False
        )
        cycle["node:oil"] = truth.fit["oil_simulated_c"].round(4)
        cycle["node:housing"] = truth.fit["housing_simulated_c"].round(4)
        cycle["time_s"] += seg * t0_gap
        frames.append(cycle)
    return pd.concat(frames, ignore_index=True)


def test_shared_and_per_trace_parameters_from_dataframes():
    m = geartherm.Model.load(MODEL)
    a, b = _trace(m, 11.0), _trace(m, 20.0)
    r = m.calibrate(traces=[a, b], names=["a", "b"], fit=[H, f"{M}@*=2:60"])
    values = dict(zip(r.parameters["key_path"], r.parameters["value"]))
    assert math.isclose(values[f"{M}@a"], 11.0, rel_tol=0.02), values
    assert math.isclose(values[f"{M}@b"], 20.0, rel_tol=0.02), values
    assert set(r.traces["trace"]) == {"a", "b"}
    assert list(r.fit.columns[:3]) == ["trace", "segment", "time_s"]
    assert "oil_band95_low_c" in r.fit.columns


def test_a_dask_fit_equals_the_local_one():
    distributed = pytest.importorskip("distributed")
    m = geartherm.Model.load(MODEL)
    a, b = _trace(m, 11.0), _trace(m, 20.0)
    kw = dict(traces=[a, b], names=["a", "b"], fit=[H, f"{M}@*=2:60"])
    local = m.calibrate(**kw)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as c, distributed.Client(c) as client:
        remote = m.calibrate(client=client, **kw)
    assert list(local.parameters["value"]) == list(remote.parameters["value"])
    assert list(local.parameters["ci95_low"]) == list(remote.parameters["ci95_low"])
    assert local.fit.equals(remote.fit)
