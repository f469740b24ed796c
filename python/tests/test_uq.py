"""Model.uq: the linear network of tests/uq_cli.rs (closed-form normal bands), through the same
use case as ``geartherm uq``; bad inputs raise with the key path."""

import math
import re
import pathlib

import pytest

import geartherm

ROOT = pathlib.Path(__file__).resolve().parents[2]


def linear_model() -> geartherm.Model:
    pt6 = (ROOT / "models" / "pt6_spur_pair.toml").read_text()
    head = pt6[: pt6.index("\n[thermal]")]
    text = head + """
[thermal]
oil_node = "oil"
initial_temp_c = 10.0

[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 2000.0

[[thermal.boundaries]]
name = "ambient"
temp_c = 20.0

[[thermal.boundaries]]
name = "coolant"
temp_c = 60.0

[[thermal.links]]
name = "oil-air"
between = ["oil", "ambient"]
conductance_w_per_k = 3.0

[[thermal.links]]
name = "oil-coolant"
between = ["oil", "coolant"]
conductance_w_per_k = 1.0
"""
    return geartherm.Model.from_text(text, "linear.toml")


def standstill(tmp_path: pathlib.Path) -> str:
    rows = ["time_s,input_speed_rpm,input_torque_nm,gear"] + [f"{k * 10},0,0,1" for k in range(101)]
    f = tmp_path / "standstill.csv"
    f.write_text("\n".join(rows) + "\n")
    return str(f)


INPUTS = [
    {"path": 'thermal.boundaries["ambient"].temp_c', "dist": "normal", "mean": 20.0, "sd": 2.0},
    {"path": 'thermal.boundaries["coolant"].temp_c', "dist": "normal", "mean": 60.0, "sd": 4.0},
]


def test_bands_match_the_normal_distribution_of_a_linear_network(tmp_path: pathlib.Path) -> None:
    r = linear_model().uq(standstill(tmp_path), inputs=INPUTS, samples=512, limits={"oil": 31.0}, threads=2)
    t = r.bands.index.to_numpy()
    e = [math.exp(-x / 500.0) for x in t]
    s_inf = math.hypot(1.5, 1.0)
    mean = [30.0 - 20.0 * x for x in e]
    sd = [(1.0 - x) * s_inf for x in e]
    med = r.bands["temp_p50_oil_c"].to_numpy()
    p95 = r.bands["temp_p95_oil_c"].to_numpy()
    for k in range(len(t)):
        assert abs(med[k] - mean[k]) < 0.15 * sd[k] + 2e-3
        assert abs(p95[k] - (mean[k] + 1.6449 * sd[k])) < 0.25 * sd[k] + 2e-3
    row = r.exceedance.iloc[0]
    assert row["node"] == "oil" and row["n"] == 512
    assert row["lo"] <= row["probability"] <= row["hi"]
    assert len(r.samples) == 512
    assert r.sobol.empty


def test_a_bad_distribution_names_the_key_path(tmp_path: pathlib.Path) -> None:
    bad = [{"path": 'thermal.boundaries["ambient"].temp_c', "dist": "normal", "mean": 20.0, "sd": -1.0}]
    with pytest.raises(
        geartherm.GearthermError,
        match=re.escape('uncertainty.inputs[0].sd = -1: must be > 0 (normal on thermal.boundaries["ambient"].temp_c)'),
    ):
        linear_model().uq(standstill(tmp_path), inputs=bad, samples=8)
    with pytest.raises(geartherm.GearthermError, match="samples"):
        linear_model().uq(standstill(tmp_path), inputs=INPUTS, samples=0)


def test_a_dask_uq_equals_the_local_one_bit_for_bit(tmp_path: pathlib.Path) -> None:
    """The samples spread over Dask workers through the runner's session (journal, resume):
    the bands, the summary and the sample table equal the local ones."""
    import distributed
    import pandas as pd

    cycle = standstill(tmp_path)
    m = linear_model()
    kw = dict(inputs=INPUTS, samples=64, limits={"oil": 31.0}, series_points=21)
    local = m.uq(cycle, threads=1, **kw)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        dask = m.uq(cycle, client=client, batch_size=8, **kw)
        into = m.uq(cycle, client=client, out=tmp_path / "dask", **kw)
        again = m.uq(cycle, client=client, out=tmp_path / "dask", **kw)  # resumed: nothing to solve
    for r in (dask, into, again):
        assert r.summary == local.summary
        pd.testing.assert_frame_equal(r.bands, local.bands, check_exact=True)
        pd.testing.assert_frame_equal(r.samples, local.samples, check_exact=True)
    assert (tmp_path / "dask" / "uq.json").is_file() and (tmp_path / "dask" / "bands.csv").is_file()


def test_check_runs_the_uncertainty_checks_of_geartherm_check() -> None:
    """`Model.check()` checks `[uncertainty]` against the model as `geartherm check` does: a key
    path the model does not have is refused with the key path named."""
    text = linear_model().text + (
        "\n[[uncertainty.inputs]]\n"
        "path = 'thermal.links[\"nope\"].conductance_w_per_k'\n"
        'dist = "uniform"\nlo = 2.0\nhi = 4.0\n'
    )
    m = geartherm.Model.from_text(text, "linear.toml")
    with pytest.raises(
        geartherm.GearthermError,
        match=re.escape(
            "uncertainty.inputs[0].path = 'thermal.links[\"nope\"].conductance_w_per_k': not a key path of the model"
        ),
    ):
        m.check()
    assert linear_model().check()["thermal_nodes"] == 1
