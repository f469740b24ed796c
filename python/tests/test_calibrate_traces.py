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


def test_options_of_one_segment_over_several_traces():
    """Priors (on a shared and on a per-trace parameter), a profile of a per-trace parameter,
    ``ar1-gls`` and a rated point over two traces: the one pipeline of the job layer, Python
    converting only. A bad prior over several traces is refused with the job layer's message."""
    m = geartherm.Model.load(MODEL)
    a, b = _trace(m, 11.0), _trace(m, 20.0)
    kw = dict(traces=[a, b], names=["a", "b"], fit=[H, f"{M}@*=2:60"])
    r = m.calibrate(
        **kw,
        prior={H: ("lognormal", 400.0, 5.0), f"{M}@b": ("normal", 19.0, 0.0005)},
        profile=[f"{M}@a"],
        residuals="ar1-gls",
        rated=(4000.0, 250.0),
    )
    assert r.summary["fit"]["residual_model"] == "ar1-gls"
    values = dict(zip(r.parameters["key_path"], r.parameters["value"]))
    # The traces are noise-free (rounded to 0.1 mK): the data outweigh both priors.
    assert math.isclose(values[f"{M}@b"], 20.0, rel_tol=0.01), values
    assert math.isclose(values[f"{M}@a"], 11.0, rel_tol=0.01), values
    assert set(r.priors["key_path"]) == {H, f"{M}@b"}
    assert ((r.priors["prior_share"] >= 0) & (r.priors["prior_share"] <= 1)).all()
    assert set(r.profiles["key_path"]) == {f"{M}@a"}
    for t in r.summary["traces"]:
        assert t["plausibility"]["rated"]["input_speed_rpm"] == pytest.approx(4000.0)
    with pytest.raises(geartherm.InputError, match="no trace is named"):
        m.calibrate(**kw, prior={f"{M}@c": ("normal", 15.0, 1.0)})


def test_a_trace_file_is_named_by_its_path_as_the_cli_names_it(tmp_path):
    """With several traces, a bad cell in a trace file: Python's message names the file by the
    path given, as `geartherm calibrate --trace PATH` does; a DataFrame by its name."""
    m = geartherm.Model.load(MODEL)
    a, b = _trace(m, 11.0), _trace(m, 20.0)
    b["node:oil"] = b["node:oil"].astype(object)
    b.loc[3, "node:oil"] = "warm"
    path_a, path_b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.to_csv(path_a, index=False)
    b.to_csv(path_b, index=False)
    with pytest.raises(geartherm.InputError) as file_err:
        m.calibrate(traces=[path_a, path_b], fit=[H])
    assert str(path_b) in str(file_err.value), str(file_err.value)
    with pytest.raises(geartherm.InputError) as frame_err:
        m.calibrate(traces=[a, b], names=["a", "b"], fit=[H])
    assert "b" in str(frame_err.value) and str(path_b) not in str(frame_err.value)
