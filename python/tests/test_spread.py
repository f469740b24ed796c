"""The model-form spread through Python: the spread block of ``losses`` and ``steady`` present
and finite for the bundled models, and the MM82 wheel's disagreement (factor 28) warned while a
windage item of a few watts is not (docs/uq.md, "Model-form spread")."""

import math
import pathlib

import pytest

import geartherm

ROOT = pathlib.Path(__file__).resolve().parents[2]
MODELS = ["at6_lepelletier", "ev_reducer", "fzg_c", "helical_stage", "mm82_wind_gearbox", "pt6_spur_pair"]


def _finite_block(block, items):
    assert len(block["items"]) == len(items)
    for it in block["items"]:
        d, lo, hi = it["default_w"], it["min_w"], it["max_w"]
        assert all(math.isfinite(x) for x in (d, lo, hi)), it
        assert lo <= d <= hi, it
        for m in it["models"]:
            if m["w"] is None:
                assert isinstance(m["not_applicable"], str), m
            else:
                assert math.isfinite(m["w"]) and lo <= m["w"] <= hi, m


@pytest.mark.filterwarnings("ignore::geartherm.RangeWarning")
@pytest.mark.parametrize("name", MODELS)
def test_losses_and_steady_carry_a_finite_spread_block(name: str) -> None:
    m = geartherm.Model.load(ROOT / "models" / f"{name}.toml")
    gear = str(m.check()["gear_states"][0])
    r = m.losses(gear, 1500.0, 100.0, 60.0, output="dict")
    _finite_block(r["spread"], r["items"])
    assert sum(len(it["models"]) - 1 for it in r["spread"]["items"]) > 0, "no item has an alternative model"
    if m.check()["thermal_nodes"]:
        try:
            s = m.steady(gear, 1500.0, 100.0, output="dict")
        except geartherm.SolveError:
            return  # no equilibrium at this point: no spread to show
        if s.get("spread") is not None:
            _finite_block(s["spread"], s["spread"]["items"])


@pytest.mark.filterwarnings("ignore::geartherm.RangeWarning")
def test_the_mm82_wheel_is_warned_and_a_few_watts_of_windage_is_not() -> None:
    m = geartherm.Model.load(ROOT / "models" / "mm82_wind_gearbox.toml")
    r = m.losses("run", 1680.0, 5000.0, 50.0)
    wheel = next(it for it in r.attrs["spread"]["items"] if it["source"] == "churning" and it["name"] == "wheel1")
    assert wheel["factor"] > 3.0
    assert any(w.startswith("item churning:wheel1: applicable models disagree by") for w in r.attrs["spread"]["warnings"])
    low = m.losses("run", 1500.0, 100.0, 60.0, output="dict")
    pinion = next(it for it in low["spread"]["items"] if it["source"] == "windage" and it["name"] == "pinion1")
    total = sum(it["w"] for it in low["items"])
    assert pinion["factor"] > 3.0 and pinion["max_w"] - pinion["min_w"] < 0.01 * total
    assert not any(w.startswith("item windage:pinion1:") for w in low["spread"]["warnings"])
    assert any(w.startswith("item churning:wheel1:") for w in low["spread"]["warnings"])
