"""The Python package: models, overrides, errors with key paths, runs as DataFrames, pickling,
GIL release, and studies locally and on a distributed.LocalCluster (equal to the last bit)."""

import math
import pickle
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import geartherm

ROOT = Path(__file__).resolve().parents[2]
AT6 = ROOT / "models" / "at6_lepelletier.toml"
FZG = ROOT / "models" / "fzg_c.toml"


@pytest.fixture(scope="module")
def at6():
    return geartherm.Model.load(AT6)


def test_load_check_info(at6):
    c = at6.check()
    assert c["gears"] > 5 and "R" in c["gear_states"]
    info = at6.info()
    assert isinstance(info, dict) and info
    assert at6.name


def test_override_changes_the_model_and_keeps_the_original(at6):
    low = at6.override({"lubrication.oil_level_mm": 40, "oil.catalogue": "fva_3a"})
    assert low.overrides == ["lubrication.oil_level_mm = 40", 'oil.catalogue = "fva_3a"']
    assert at6.overrides == []
    a = at6.losses("3", 2500, 150, 80)
    b = low.losses("3", 2500, 150, 80)
    assert not a.equals(b)


def test_invalid_override_raises_with_the_key_path(at6):
    with pytest.raises(geartherm.ModelError) as e:
        at6.override({'thermal.coolers["atf_cooler"].effectiveness': 1.4})
    assert e.value.path == "thermal.coolers[0].effectiveness"
    assert any("override" in p[2] for p in e.value.problems)
    with pytest.raises(geartherm.ModelError) as e:
        at6.override({'thermal.links["nope"].area_m2': 1.0})
    assert "no entry named" in str(e.value)
    with pytest.raises(geartherm.ModelError):
        geartherm.Model.from_text("[model]\nname = 'x'\n")
    with pytest.raises(OSError):
        geartherm.Model.load(ROOT / "no_such_model.toml")


def test_bad_arguments_and_solver_failures_are_exceptions(at6):
    with pytest.raises(geartherm.InputError):
        at6.run(cycle="no_such_cycle")
    with pytest.raises(geartherm.InputError):
        at6.steady(gear="9", speed_rpm=1000, torque_nm=10)
    with pytest.raises(geartherm.SolveError):
        at6.run(cycle="hwfet", max_steps=3, summary_only=True)
    assert issubclass(geartherm.SolveError, geartherm.GearthermError)


def test_run_returns_a_dataframe_with_units_and_a_summary_dict(at6):
    r = at6.run(cycle="hwfet")
    ts = r.timeseries
    assert isinstance(ts, pd.DataFrame)
    assert {"time_s", "vehicle_speed_kmh", "temp_sump_c", "loss_total_w"} <= set(ts.columns)
    assert ts["time_s"].iloc[-1] == pytest.approx(r.summary["duration_s"] + ts["time_s"].iloc[0])
    assert r.summary["energy_lost_j"]["total"] > 0
    # The summary's max sump temperature is the max of the time series.
    assert ts["temp_sump_c"].max() == pytest.approx(r.summary["temperatures_c"]["sump"]["max"], abs=1e-9)
    s = at6.run(cycle="hwfet", summary_only=True)
    assert s.timeseries is None
    # Summary-only integrates the same equations with energies per source instead of per item:
    # at the default tolerance the two differ by their integration error (their step sequences
    # differ: the state vectors differ), with rtol and atol both tight they agree to 5e-10.
    assert s.summary["energy_lost_j"]["total"] == pytest.approx(r.summary["energy_lost_j"]["total"], rel=1e-5)
    tight = [
        at6.run(cycle="hwfet", rtol=1e-10, atol=1e-10, summary_only=so).summary["energy_lost_j"]["total"]
        for so in (False, True)
    ]
    assert tight[1] == pytest.approx(tight[0], rel=1e-8)


def test_steady_and_map(at6):
    st = at6.steady(gear="6", speed_rpm=2000, torque_nm=100, output="dict")
    assert st["loss_total_w"] > 0 and 0 < st["efficiency"] < 1
    assert set(st["temperatures_c"]) >= {"sump", "housing"}
    m = at6.map(gear="6", speed_rpm=[1500, 2500], torque_nm=[50, 150])
    assert isinstance(m, pd.DataFrame) and len(m) == 4


def test_rating_puts_the_oil_at_the_limit():
    fzg = geartherm.Model.load(FZG)
    r = fzg.rating("1", [1000, 3000], 100.0)
    assert list(r["status"]) == ["rated", "rated"]
    for _, p in r.iterrows():
        s = fzg.steady("1", p["speed_rpm"], p["rated_torque_nm"])
        assert abs(s["temp_oil_c"].iloc[0] - 100.0) <= 0.01
    assert fzg.rating("1", 3000, 30.0, output="dict")["points"][0]["status"] == "limit_at_minimum"


def test_models_and_results_pickle(at6):
    m = at6.override({"lubrication.oil_level_mm": 50})
    m2 = pickle.loads(pickle.dumps(m))
    assert m2.overrides == m.overrides and m2.text == m.text
    r = m.run(cycle="hwfet", summary_only=True)
    r2 = pickle.loads(pickle.dumps(r))
    assert r2.summary == r.summary
    assert m2.run(cycle="hwfet", summary_only=True).summary["energy_lost_j"] == r.summary["energy_lost_j"]


def test_the_gil_is_released_during_a_solve(at6, tmp_path):
    # Six WLTCs back to back (10 800 s): one WLTC at rtol 1e-11 integrates in ~0.04 s, too
    # short for the counter below to be measured against.
    rows = (ROOT / "models" / "cycles" / "wltc_class3b.csv").read_text().splitlines()[1:]
    wltc = [tuple(float(v) for v in r.split(",")) for r in rows if r.strip()]
    long_cycle = tmp_path / "wltc_x6.csv"
    lines = ["time_s,speed_kmh"]
    for k in range(6):
        lines += [f"{t + 1800.0 * k + k:g},{v}" for t, v in wltc]
    long_cycle.write_text("\n".join(lines) + "\n")
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    t0 = time.perf_counter()
    # One long native call (six WLTCs at rtol 1e-11: ~0.2 s) rather than a loop of
    # short ones, between which the GIL would be free anyway.
    at6.run(cycle=long_cycle, rtol=1e-11, atol=1e-11, summary_only=True)
    t1 = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if t0 < x < t1]
    # With the GIL held the counter would not run at all during the solve.
    assert (t1 - t0) > 0.05
    assert len(during) >= 10, (len(during), t1 - t0)


PARAMS = {
    "lubrication.oil_level_mm": {"range": [40.0, 80.0]},
    "oil.catalogue": {"values": ["dexron_vi_atf", "fva_3a"]},
    'thermal.links["housing-air"].h_table.h_w_per_m2k': {"scale": [0.5, 2.0]},
    'thermal.coolers["atf_cooler"].effectiveness': {"range": [0.5, 1.2]},
}
PLAN = {"plan": "lhs", "cases": 8, "seed": 11}
JOB = {"kind": "run", "cycles": ["hwfet"]}


@pytest.fixture(scope="module")
def local_study():
    return geartherm.study(AT6, PARAMS, JOB, PLAN)


def test_local_study_rows_and_failures(local_study):
    df = local_study
    assert len(df) == 8
    assert list(df.columns[:3]) == ["case", "sample", "job"]
    assert set(df.status) == {"ok", "invalid"}  # effectiveness > 1 is invalid
    bad = df[df.status == "invalid"]
    assert bad.message.str.contains("effectiveness").all()
    assert bad["energy_total_j"].isna().all()
    ok = df[df.status == "ok"]
    assert (ok["energy_total_j"] > 0).all() and ok["temp_max_sump_c"].notna().all()


def test_a_study_case_equals_a_direct_run(local_study):
    row = local_study[local_study.status == "ok"].iloc[0]
    scale = row['thermal.links["housing-air"].h_table.h_w_per_m2k (scale)']
    base = geartherm.Model.load(AT6)
    h = [12.0, 22.0, 32.0, 45.0, 55.0]
    m = base.override(
        {
            "lubrication.oil_level_mm": row["lubrication.oil_level_mm"],
            "oil.catalogue": row["oil.catalogue"],
            'thermal.links["housing-air"].h_table.h_w_per_m2k': [x * scale for x in h],
            'thermal.coolers["atf_cooler"].effectiveness': row['thermal.coolers["atf_cooler"].effectiveness'],
        }
    )
    s = m.run(cycle="hwfet", summary_only=True).summary
    assert s["energy_lost_j"]["total"] == row["energy_total_j"]
    assert s["temperatures_c"]["sump"]["max"] == row["temp_max_sump_c"]


def test_study_on_a_local_cluster_equals_the_local_run_to_the_last_bit(local_study):
    import distributed as distributed
    with distributed.LocalCluster(
        n_workers=3, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        pids = set(client.run(lambda: __import__("os").getpid()).values())
        assert len(pids) == 3
        dd = geartherm.study(AT6, PARAMS, JOB, PLAN, client=client, batch_size=3, threads_per_task=1)
    pd.testing.assert_frame_equal(dd, local_study, check_exact=True)
    # Bit-for-bit, NaN in the same places.
    for col in local_study.columns:
        a, b = local_study[col].tolist(), dd[col].tolist()
        for x, y in zip(a, b):
            assert (x == y) or (isinstance(x, float) and math.isnan(x) and math.isnan(y)), col


def test_study_commands_are_stand_alone_cli_lines():
    cmds = geartherm.study_commands(AT6, PARAMS, JOB, PLAN)
    assert len(cmds) == 8
    assert all(c.startswith("geartherm run ") and "--set" in c for c in cmds)


def test_a_subset_of_cases_gives_the_same_rows(local_study):
    # The rows come in case order whatever the order of `cases`.
    sub = geartherm.study(AT6, PARAMS, JOB, PLAN, cases=[5, 1])
    assert list(sub.case) == [local_study.case[1], local_study.case[5]]
    for k, i in enumerate([1, 5]):
        assert sub.iloc[k].equals(local_study.iloc[i]) or all(
            (a == b) or (a != a and b != b) for a, b in zip(sub.iloc[k], local_study.iloc[i])
        )
