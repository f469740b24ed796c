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
    with pytest.raises(geartherm.GearthermError, match="band_quantile = normal"):
        base.calibrate(rig(), fit=[H], band_quantile="normal")


def test_the_band_multiplier_per_channel():
    base = geartherm.Model.load(MODEL)
    truth = base.override({H: 400.0, M: 11.0})
    sim = truth.calibrate(rig(), holdout=[(0.0, 1e9)]).fit
    values = [(a + 0.05 * math.sin(k), b - 0.05 * math.cos(k))
              for k, (a, b) in enumerate(zip(sim["oil_simulated_c"], sim["housing_simulated_c"]))]
    kw = dict(fit=[H, M], holdout=[(2400.0, 3600.0)])
    # 21 fitted rows per channel are too few for the empirical quantile: the default is t's.
    r = base.calibrate(rig(values), **kw)
    t975 = r.summary["fit"]["t975"]
    assert (r.errors["band_quantile"] == "t").all() and (r.errors["band_multiplier"] == t975).all()
    t = base.calibrate(rig(values), band_quantile="t", **kw)
    assert (t.errors["band_multiplier"] == t975).all()
    assert list(t.fit["oil_band95_k"]) == list(r.fit["oil_band95_k"])


def test_priors_profiles_bands_and_losses_as_dataframes(tmp_path):
    base = geartherm.Model.load(MODEL)
    truth = base.override({H: 400.0, M: 11.0})
    sim = truth.calibrate(rig(), holdout=[(0.0, 1e9)]).fit
    values = [(a + 0.05 * math.sin(k), b - 0.05 * math.cos(k))
              for k, (a, b) in enumerate(zip(sim["oil_simulated_c"], sim["housing_simulated_c"]))]
    kw = dict(fit=[H, M], holdout=[(2400.0, 3600.0)], residuals="independent")
    free = base.calibrate(rig(values), **kw)
    r = base.calibrate(rig(values), prior={M: ("normal", 11.0, 100.0)}, profile=[M],
                       gearbox_kind="wind-turbine", rated=(3000.0, 200.0), **kw)
    # A wide prior: the fit is the one without it; its influence is reported.
    v0 = free.parameters.set_index("key_path").loc[M, "value"]
    assert math.isclose(r.parameters.set_index("key_path").loc[M, "value"], v0, rel_tol=1e-3)
    pr = r.priors.set_index("key_path").loc[M]
    assert pr["distribution"] == "normal" and pr["prior_share"] < 0.01
    # The profile: a grid around the fitted value, its least point at 0.
    assert set(r.profiles["key_path"]) == {M} and len(r.profiles) >= 9
    assert r.profiles["statistic"].min() == 0.0
    assert r.summary["profiles"][0]["ci95_low"] < v0 < r.summary["profiles"][0]["ci95_high"]
    # Bands as columns: the simulated value ± the half-width.
    f = r.fit
    assert ((f["oil_band95_low_c"] < f["oil_simulated_c"]) & (f["oil_simulated_c"] < f["oil_band95_high_c"])).all()
    # Losses per source at the highest-power rows and the rated point.
    assert set(r.plausibility["at"]) == {"highest_power", "rated"}
    assert (r.plausibility["loss_w"] >= 0).all()
    # A priors file as the CLI reads it; a negative width is an InputError naming the key path.
    good = tmp_path / "priors.toml"
    good.write_text(f"[[prior]]\nkey = '{M}'\ndistribution = 'normal'\nmean = 11\nsd = 100\n")
    g = base.calibrate(rig(values), priors_file=good, **kw)
    assert len(g.priors) == 1
    bad = tmp_path / "bad.toml"
    bad.write_text(f"[[prior]]\nkey = '{M}'\ndistribution = 'normal'\nmean = 11\nsd = -1\n")
    with pytest.raises(geartherm.GearthermError, match=r"bad.toml: prior\[0\].sd = -1"):
        base.calibrate(rig(values), priors_file=bad, **kw)
    with pytest.raises(geartherm.GearthermError, match="sd"):
        base.calibrate(rig(values), prior={M: ("normal", 11.0, -1.0)}, **kw)
