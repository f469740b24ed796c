"""What a Python user needs in a first hour: the CLI from pip, models back from studies and
overrides, calibration results that save and plot, errors with their fields, frames, Parquet,
warnings that filter, and real SCADA traces."""

import json
from html import escape as html_escape
import math
import os
import pickle
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

import pandas as pd
import pytest

import geartherm

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("GEARTHERM_BIN", Path(sys.executable).parent / "geartherm"))
MODELS = sorted(p for p in (ROOT / "models").glob("*.toml") if p.name not in ("oils.toml", "bearings.toml"))
ENGIE = ROOT.parent / "shared" / "data" / "engie_la_haute_borne"
STAGE = ROOT / "models" / "helical_stage.toml"
H = 'thermal.links["oil-housing"].h_w_per_m2k'
M = 'thermal.nodes["housing"].mass_kg'


def test_pip_installs_the_geartherm_command_into_the_same_library():
    out = subprocess.run([str(BIN), "--version"], capture_output=True, text=True, check=True).stdout
    assert out.strip() == f"geartherm {geartherm.__version__}"
    bad = subprocess.run([str(BIN), "check", str(ROOT / "no_such.toml")], capture_output=True, text=True)
    assert bad.returncode == 3 and "no_such.toml" in bad.stderr
    usage = subprocess.run([str(BIN), "run"], capture_output=True, text=True)
    assert usage.returncode == 1 and "Usage" in usage.stderr


# --- models from anything ---------------------------------------------------------------------


def _overrides(path):
    doc = tomllib.loads(path.read_text())
    ovs = {}
    gears = doc.get("gears", [])
    if gears:
        ovs["gears[0].face_width_mm"] = float(gears[0]["face_width_mm"]) * 1.05
    if "oil_level_mm" in doc.get("lubrication", {}):
        ovs["lubrication.oil_level_mm"] = float(doc["lubrication"]["oil_level_mm"]) + 1.0
    nodes = doc.get("thermal", {}).get("nodes", [])
    if nodes and "mass_kg" in nodes[0]:
        ovs[f'thermal.nodes["{nodes[0]["name"]}"].mass_kg'] = float(nodes[0]["mass_kg"]) * 1.1
    return ovs


@pytest.mark.parametrize("path", MODELS, ids=[p.stem for p in MODELS])
def test_to_toml_writes_the_overrides_in_and_reads_back_equal(path, tmp_path):
    base = geartherm.Model.load(path)
    ovs = _overrides(path)
    assert len(ovs) >= 2, ovs
    m = base.override(ovs)
    text = m.to_toml()
    back = geartherm.Model.from_text(text, "back.toml")
    assert back == m and back != base and back.overrides == []
    # The file the CLI reads, too.
    (tmp_path / "m.toml").write_text(text)
    assert geartherm.Model.load(tmp_path / "m.toml") == m
    assert subprocess.run([str(BIN), "check", str(tmp_path / "m.toml")], capture_output=True).returncode == 0


def test_a_study_case_is_a_model_whose_run_is_its_row():
    s = geartherm.Study(
        ROOT / "models" / "at6_lepelletier.toml",
        {"lubrication.oil_level_mm": {"range": [40, 80]}, "oil.catalogue": {"values": ["dexron_vi_atf", "fva_3a"]}},
        {"kind": "run", "cycles": ["hwfet"]},
        {"plan": "lhs", "cases": 4, "seed": 3},
    )
    df = s.run(progress=False)
    for i in range(len(df)):
        job = s.job(i)
        assert job["kind"] == "run"
        o = job["options"]
        m = s.model(i)
        assert m.overrides == [f"lubrication.oil_level_mm = {float(df['lubrication.oil_level_mm'][i])!r}", f'oil.catalogue = "{df["oil.catalogue"][i]}"']
        assert o["summary_only"] is True
        r = m.run(**o)
        row = df.iloc[i]
        assert row["energy_total_j"] == r.summary["energy_lost_j"]["total"]
        assert row["cycle_efficiency"] == r.summary["cycle_efficiency"]
        assert row["temp_max_sump_c"] == r.summary["temperatures_c"]["sump"]["max"]
        assert geartherm.Model.from_text(m.to_toml()) == m


# --- calibration results ------------------------------------------------------------------------


def _rig(values=None):
    rows = []
    for k in range(31):
        w, t = (3000.0, 200.0) if k < 15 else (1500.0, 100.0)
        oil, housing = values[k] if values is not None else (30.0, 30.0)
        rows.append({"time_s": 120.0 * k, "input_speed_rpm": w, "input_torque_nm": t, "gear": "1",
                     "boundary:ambient": 20.0, "node:oil": oil, "node:housing": housing})
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def measured():
    truth = geartherm.Model.load(STAGE).override({H: 400.0, M: 11.0})
    sim = truth.calibrate(_rig(), holdout=[(0.0, 1e9)]).fit
    return _rig(list(zip(sim["oil_simulated_c"], sim["housing_simulated_c"])))


def test_calibration_write_is_the_cli_directory_byte_for_byte(measured, tmp_path):
    trace = tmp_path / "trace.csv"
    measured.to_csv(trace, index=False)
    cli = tmp_path / "cli"
    subprocess.run(
        [str(BIN), "calibrate", str(STAGE), "--trace", str(trace), "--fit", H, "--fit", f"{M}=2:60",
         "--holdout", "2400:3600", "--out", str(cli)],
        check=True, capture_output=True,
    )
    r = geartherm.Model.load(STAGE).calibrate(trace, fit=[H, f"{M}=2:60"], holdout=[(2400, 3600)])
    py = r.write(tmp_path / "py")
    names = sorted(p.name for p in cli.iterdir() if not p.name.startswith("."))
    assert names == sorted(p.name for p in py.iterdir())
    assert names == ["calibrated.toml", "calibration.json", "calibration.png", "cycle.csv", "fit.csv"]
    for n in names:
        if n == "calibration.json":
            a, b = json.loads((cli / n).read_text()), json.loads((py / n).read_text())
            a["fit"].pop("wall_time_s"), b["fit"].pop("wall_time_s")
            assert a == b
        else:
            assert (cli / n).read_bytes() == (py / n).read_bytes(), n
    # The parameters frame has the columns the docs list.
    assert {"key_path", "start", "value", "lower_bound", "upper_bound", "influence_k", "ci95_low", "ci95_high"} <= set(r.parameters.columns)
    html = r._repr_html_()
    assert "<table>" in html and html_escape(H) in html and "RMSE" in html
    fig = r.plot()
    assert len(fig.axes) == 2 and len(fig.axes[0].lines) == 4
    again = pickle.loads(pickle.dumps(r))
    again.write(tmp_path / "again")
    assert (tmp_path / "again" / "fit.csv").read_bytes() == (cli / "fit.csv").read_bytes()


# --- errors with their fields --------------------------------------------------------------------


def test_model_errors_carry_file_key_path_typed_value_and_range():
    at6 = geartherm.Model.load(ROOT / "models" / "at6_lepelletier.toml")
    with pytest.raises(geartherm.ModelError) as e:
        at6.override({'thermal.coolers["atf_cooler"].effectiveness': 1.4})
    assert e.value.path == "thermal.coolers[0].effectiveness"
    assert e.value.value == 1.4 and isinstance(e.value.value, float)
    assert "[0, 1]" in e.value.allowed
    assert e.value.file.endswith("at6_lepelletier.toml")
    text = (ROOT / "models" / "at6_lepelletier.toml").read_text()
    with pytest.raises(geartherm.ModelError) as e:
        geartherm.Model.from_text(text.replace('name = "s1_sun"', 'name = "s1_sunn"', 1), "bad.toml")
    # four references to the old name, each a problem of its own; no cascade from the failed set
    assert len(e.value.problems) == 4, e.value.problems
    assert [p[0] for p in e.value.problems] == [
        "planetary_sets[0].sun",
        "lubrication.centre_height_mm.s1_sun",
        "lubrication.centre_height_mm.s1_sunn",
        "thermal.nodes[2].gears[0]",
    ], e.value.problems
    assert e.value.file == "bad.toml" and "s1_sun" in str(e.value)


def test_input_errors_carry_their_fields():
    at6 = geartherm.Model.load(ROOT / "models" / "at6_lepelletier.toml")
    with pytest.raises(geartherm.InputError) as e:
        at6.run(cycle="no_such_cycle")
    assert e.value.path == "cycle" and e.value.value == "no_such_cycle" and "wltc" in e.value.allowed
    with pytest.raises(geartherm.InputError) as e:
        at6.steady(gear="6", speed_rpm=60000, torque_nm=10)
    assert e.value.path == "speed_rpm" and e.value.value == 60000.0 and "50000" in e.value.allowed.replace(" ", "")
    assert isinstance(e.value.value, float)
    with pytest.raises(geartherm.InputError) as e:
        at6.steady(gear="9", speed_rpm=1000, torque_nm=10)
    assert (e.value.path, e.value.value) == ("gear", "9") and "R" in e.value.allowed
    bad = _rig()
    bad.loc[3, "node:oil"] = 900.0
    with pytest.raises(geartherm.InputError) as e:
        geartherm.Model.load(STAGE).calibrate(bad, fit=[H], name="rig.csv")
    assert (e.value.file, e.value.line, e.value.path, e.value.value) == ("rig.csv", 5, "node:oil", 900.0)
    assert "[-60, 400]" in e.value.allowed
    assert pickle.loads(pickle.dumps(e.value)).line == 5


# --- frames, Parquet, warnings ----------------------------------------------------------------


def test_losses_steady_rating_are_frames_and_dicts_on_request():
    fzg = geartherm.Model.load(ROOT / "models" / "fzg_c.toml")
    lo = fzg.losses("1", 1500, 100, 60)
    d = fzg.losses("1", 1500, 100, 60, output="dict")
    assert list(lo.columns[:3]) == ["source", "name", "w"] and len(lo) == len(d["items"])
    assert lo["w"].sum() == pytest.approx(d["loss_total_w"], rel=1e-12)
    st = fzg.steady("1", 1500, 100)
    assert len(st) == 1 and st["loss_total_w"].iloc[0] == st.attrs["loss_total_w"]
    mp = fzg.map("1", [1500], [100])
    for c, d in (("loss_total_w", "loss_total_w"), ("efficiency", "efficiency"), ("temp_oil_c", "oil_temp_c")):
        assert st[c].iloc[0] == pytest.approx(mp[d].iloc[0], rel=1e-9), c
    ra = fzg.rating("1", [1000, 2000], 90.0)
    assert list(ra["speed_rpm"]) == [1000.0, 2000.0] and (ra["oil_temp_c"] <= 90.0 + 1e-6).all()


def test_time_series_to_parquet_with_the_csv_schema(tmp_path):
    r = geartherm.Model.load(ROOT / "models" / "fzg_c.toml").run(
        cycle=pd.DataFrame({"time_s": [0.0, 600.0], "input_speed_rpm": [1500.0, 1500.0], "input_torque_nm": [100.0, 100.0], "gear": ["1", "1"]})
    )
    d = r.write(tmp_path / "run", parquet=True)
    pq = pd.read_parquet(d / "timeseries.parquet")
    pd.testing.assert_frame_equal(pq, r.timeseries, check_exact=True)
    assert geartherm.read_run(d) == r


def test_range_warnings_filter_by_a_stable_path_on_the_command_line():
    code = "import geartherm, warnings; geartherm.Model.load(%r).run(cycle='hwfet', summary_only=True); print('ran')" % str(ROOT / "models" / "at6_lepelletier.toml")
    shown = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "RangeWarning" in shown.stderr and shown.stderr.count("RangeWarning") == 1
    for opt in ("ignore::geartherm.RangeWarning", "ignore::geartherm.errors.RangeWarning"):
        quiet = subprocess.run([sys.executable, "-W", opt, "-c", code], capture_output=True, text=True, check=True)
        assert quiet.stdout.strip() == "ran" and "RangeWarning" not in quiet.stderr, quiet.stderr


# --- real SCADA traces ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def engie(tmp_path_factory):
    out = tmp_path_factory.mktemp("engie")
    subprocess.run([sys.executable, str(ROOT / "scripts" / "engie_traces.py"), str(ENGIE), str(out)], check=True, capture_output=True)
    return out


def test_the_engie_2013_2018_files_read_as_traces_from_python_and_the_cli(engie):
    for turbine in ("R80711", "R80721"):
        path = engie / f"{turbine}_2013-2020.csv"
        t = geartherm.read_trace(path)
        s = t.summary
        assert len(t.segments) == len(s["segments"]) > 10
        assert t.dropped_rows > 0 and sum(t.missing_cells.values()) >= t.dropped_rows
        assert s["kept_rows"] + s["dropped_rows"] == s["rows"] == len(path.read_text().splitlines()) - 1
        assert sum(len(x) for x in t.segments) == s["kept_rows"]
        for seg, off in zip(t.segments, t.offsets_s):
            assert seg["time_s"].iloc[0] == 0.0 and seg["node:sump"].notna().all()
        assert t.offsets_s == sorted(t.offsets_s)
        cli = subprocess.run([str(BIN), "trace", str(path), "--json"], capture_output=True, text=True, check=True)
        assert json.loads(cli.stdout) == s
        with pytest.raises(geartherm.InputError) as e:
            geartherm.read_trace(path, missing="refuse")
        assert e.value.line is not None and e.value.value == ""
    spring = geartherm.read_trace(engie / "R80711_2017-spring.csv")
    assert len(spring.segments) == 1 and spring.dropped_rows == 0 and len(spring.segments[0]) == 3910
