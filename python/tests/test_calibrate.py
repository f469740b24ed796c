"""Model.calibrate: the same job as ``geartherm calibrate``, the trace as a DataFrame."""
import math
import os

import pandas as pd
import pytest

import geartherm

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODEL = os.path.join(ROOT, "models", "helical_stage.toml")
H = 'thermal.links["oil-housing"].h_w_per_m2k'
M = 'thermal.nodes["housing"].mass_kg'


def rig(values=None):
    rows = []
    for k in range(31):
        w, t = (3000.0, 200.0) if k < 15 else (1500.0, 100.0)
        oil, housing = values[k] if values is not None else (30.0, 30.0)
        rows.append({"time_s": 120.0 * k, "input_speed_rpm": w, "input_torque_nm": t, "gear": "1",
                     "boundary:ambient": 20.0, "node:oil": oil, "node:housing": housing})
    return pd.DataFrame(rows)


def test_calibrate_recovers_parameters_from_a_dataframe():
    base = geartherm.Model.load(MODEL)
    truth = base.override({H: 400.0, M: 11.0})
    sim = truth.calibrate(rig(), holdout=[(0.0, 1e9)]).fit
    values = list(zip(sim["oil_simulated_c"], sim["housing_simulated_c"]))
    r = base.calibrate(rig(values), fit=[H, f"{M}=2:60"], holdout=[(2400.0, 3600.0)])
    p = r.parameters.set_index("key_path")
    assert math.isclose(p.loc[H, "value"], 400.0, rel_tol=1e-4)
    assert math.isclose(p.loc[M, "value"], 11.0, rel_tol=1e-4)
    assert list(r.correlation.index) == [H, M]
    assert set(r.errors["rows_of"]) == {"fitted", "holdout"}
    assert (r.errors["rmse_k"] < 1e-2).all()
    assert len(r.fit) == 31 and "oil_residual_k" in r.fit.columns
    cal = r.calibrated
    assert cal.name == base.name
    assert "400" in r.calibrated_text


def test_bad_traces_are_refused_like_the_cli():
    base = geartherm.Model.load(MODEL)
    bad = rig().rename(columns={"node:housing": "node:case"})
    with pytest.raises(geartherm.GearthermError, match="node:case"):
        base.calibrate(bad, fit=[H])
    # A NaN is an empty cell in the CSV text: its row is dropped and counted (a warning), or,
    # with missing="refuse", refused naming the line and the column.
    nan = rig()
    nan.loc[3, "node:oil"] = float("nan")
    r = base.calibrate(nan, fit=[H])
    assert len(r.fit) == 30 and any("1 row(s) with empty cells dropped" in w and "node:oil 1" in w for w in r.warnings)
    with pytest.raises(geartherm.InputError, match="node:oil") as e:
        base.calibrate(nan, fit=[H], missing="refuse")
    assert e.value.line == 5 and e.value.path == "node:oil"
    with pytest.raises(geartherm.GearthermError, match="max_iterations"):
        base.calibrate(rig(), fit=[H], max_iterations=0)
