"""The FMU export checked by a real importer, FMPy (docs/fmu.md): the description validates,
`simulate_fmu` over the WLTC with a `geartherm run`'s inputs reproduces the run's temperatures
and energies, the result does not depend on the communication step beyond the solver's
tolerance, bad values are FMI errors the instance recovers from, and 1000 instantiate / reset /
free cycles leave the memory flat, a tunable parameter changed between steps equals a run of two
segments. Figures are printed (`pytest -s`).

The FMUs are exported with the runtime library the wheel carries (`geartherm/_bin/
libgeartherm_fmu.so`, `Model.to_fmu` with no `runtime`), which is checked self-contained (ldd,
nm). An installation without it (e.g. a `maturin develop` build) skips these tests, unless
`GEARTHERM_FMU_REQUIRED=1` (CI) makes that a failure.
"""

import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import geartherm

fmpy = pytest.importorskip("fmpy")
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
AT6 = ROOT / "models" / "at6_lepelletier.toml"
RUNTIME = Path(geartherm._cli.BIN_DIR) / "libgeartherm_fmu.so"
REQUIRED = os.environ.get("GEARTHERM_FMU_REQUIRED") == "1"

pytestmark = pytest.mark.skipif(
    not RUNTIME.is_file() and not REQUIRED,
    reason=f"no FMU runtime library at {RUNTIME} (`pip install ./python` puts it there)",
)

KELVIN = 273.15


def _fix_fmpy_input_derivatives():
    """FMPy 0.3.32's `Input` allocates room for 9 input derivatives whatever the number of
    continuous inputs (`derivatives=(value_type * 9)()` in fmpy/simulation.py), so
    `set_input_derivatives=True` fails unless an FMU has exactly 9: give it one per input."""
    import fmpy.simulation as sim

    init = sim.Input.__init__
    if getattr(init, "_geartherm_fixed", False):
        return

    def fixed(self, *args, **kw):
        init(self, *args, **kw)
        self.continuous = [c._replace(derivatives=(c.derivatives._type_ * len(c.vrs))()) for c in self.continuous]

    fixed._geartherm_fixed = True  # type: ignore[attr-defined]
    sim.Input.__init__ = fixed  # type: ignore[method-assign]


_fix_fmpy_input_derivatives()


def _cli():
    exe = shutil.which("geartherm")
    return [exe] if exe else [sys.executable, "-c", "import sys, geartherm._cli as c; sys.exit(c.main())"]


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    return tmp_path_factory.mktemp("fmu")


@pytest.fixture(scope="module")
def fmu(work):
    assert "GEARTHERM_FMU_RUNTIME" not in os.environ
    path = geartherm.Model.load(AT6).to_fmu(work / "at6.fmu")
    return path


@pytest.fixture(scope="module")
def run(work):
    out = work / "run"
    subprocess.run(_cli() + ["run", str(AT6), "--cycle", "wltc", "--out", str(out), "--quiet"], check=True)
    with open(out / "timeseries.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    summary = json.loads((out / "summary.json").read_text())
    return rows, summary


def _description(fmu):
    return fmpy.read_model_description(fmu)


def _gear_index(md):
    desc = next(v for v in md.modelVariables if v.name == "gear").description
    return {name: int(i) for i, name in re.findall(r"(\d+) = ([^,]+)", desc)}


def _nodes(md):
    return [v.name[2:] for v in md.modelVariables if v.name.startswith("T.")]


def _inputs(rows, md, block=1):
    """The run's inputs as an FMPy signal: speed, loss-free torque, vehicle speed and gear held
    over each sample, boundaries linear between samples. With `block` > 1, only every block-th
    sample (a coarser rig cycle: inputs held over `block` seconds, boundaries still linear
    between the block's ends, which holds for the AT6's coolant curve, whose kinks lie on
    multiples of 10 s)."""
    gears = _gear_index(md)
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    dtype = [("time", np.float64)] + [(n, np.int32 if n == "gear" else np.float64) for n in names]

    def held(r):
        w = float(r["input_speed_rpm"]) * math.pi / 30.0
        # timeseries.csv's input torque adds the shaft's losses to the loss-free torque, whose
        # power is the output power.
        t = float(r["output_power_w"]) / w if w > 0.0 else float(r["input_torque_nm"])
        return {"input_speed": w, "input_torque": t, "vehicle_speed": float(r["vehicle_speed_kmh"]) / 3.6,
                "gear": gears[r["gear"]]}

    def boundaries(r):
        return {f"T_boundary.{b}": float(r[f"temp_{b}_c"]) + KELVIN for b in ("ambient", "coolant")}

    rows = rows[::block]
    # FMPy holds the first sample with a zero derivative and, between samples, sets the
    # derivative of the piece before the current time; at a repeated time (an event) it takes
    # the piece after. Every sample time is repeated, and t = 0 is preceded by a still piece.
    first = {**held(rows[0]), **boundaries(rows[0])}
    out = [tuple([t] + [first[n] for n in names]) for t in (-1.0, 0.0)]
    for k in range(len(rows) - 1):
        h = held(rows[k])
        for r in (rows[k], rows[k + 1]):
            v = {**h, **boundaries(r)}
            out.append(tuple([float(r["time_s"])] + [v[n] for n in names]))
    return np.array(out, dtype=dtype)


def _simulate(fmu, signals, step, stop, outputs, **kw):
    return fmpy.simulate_fmu(fmu, start_time=0.0, stop_time=stop, output_interval=step, input=signals,
                             set_input_derivatives=True, output=outputs, **kw)


def test_validate_fmu_reports_nothing(fmu):
    problems = validate_fmu(fmu)
    print(f"\nfmpy.validate_fmu({Path(fmu).name}): {len(problems)} problems {problems}")
    assert problems == []


def test_simulate_fmu_reproduces_the_wltc_run(fmu, run):
    rows, summary = run
    md = _description(fmu)
    nodes = _nodes(md)
    sources = [s for s in summary["energy_lost_j"] if s != "total" and f"E_loss.{s}" in
               {v.name for v in md.modelVariables}]
    outputs = [f"T.{n}" for n in nodes] + [f"E_loss.{s}" for s in sources]
    t0 = time.perf_counter()
    res = _simulate(fmu, _inputs(rows, md), 1.0, float(rows[-1]["time_s"]), outputs)
    wall = time.perf_counter() - t0
    assert len(res) == len(rows)
    dt = max(abs(res[f"T.{n}"][k] - (float(r[f"temp_{n}_c"]) + KELVIN))
             for k, r in enumerate(rows) for n in nodes)
    de = max(abs(res[f"E_loss.{s}"][-1] - summary["energy_lost_j"][s]) / abs(summary["energy_lost_j"][s])
             for s in sources if summary["energy_lost_j"][s] != 0.0)
    print(f"\nFMPy simulate_fmu, AT6 WLTC, 1 s steps ({len(rows)} points, {wall:.2f} s): "
          f"max |T_fmu - T_run| = {dt:.3e} K over {len(nodes)} nodes; "
          f"energy per source at the end, max relative difference {de:.3e} ({len(sources)} sources)")
    assert dt <= 1e-6
    assert de <= 1e-9


def _sweep(fmu, signals, outs, rtol):
    """Temperatures at the 10 s points for every communication step, and their largest
    difference from the 10 s step's."""
    results = {}
    for h in (10.0, 5.0, 1.0, 0.1, 0.01):
        t0 = time.perf_counter()
        r = _simulate(fmu, signals, h, 600.0, outs, start_values={"rtol": rtol})
        grid = np.isclose(r["time"] / 10.0, np.round(r["time"] / 10.0), atol=1e-9, rtol=0)
        results[h] = (r[grid], time.perf_counter() - t0)
    ref = results[10.0][0]
    t_max = max(float(np.max(ref[o])) for o in outs)
    print(f"\nstep-size sweep, AT6 WLTC 0-600 s, inputs held over 10 s, rtol {rtol:g} (rtol x max T = {rtol * t_max:.3e} K):")
    diffs = {}
    for h, (r, wall) in results.items():
        assert len(r) == len(ref) == 61
        diffs[h] = max(float(np.max(np.abs(r[o] - ref[o]))) for o in outs)
        print(f"  step {h:>5g} s: max |T - T(10 s step)| = {diffs[h]:.3e} K, {wall:.2f} s")
    return diffs, t_max


def test_step_size_sweep(fmu, run):
    """The first 600 s of the WLTC as a rig cycle held over 10 s blocks: every communication
    step from 10 s to 0.01 s gives the temperatures of the 10 s step at the 10 s points within
    rtol x the largest temperature at the default tolerance, and the differences shrink with
    the tolerance (integration error, not a coupling error)."""
    rows, _ = run
    md = _description(fmu)
    signals = _inputs(rows[:601], md, block=10)
    outs = [f"T.{n}" for n in _nodes(md)]
    coarse, t_max = _sweep(fmu, signals, outs, 1e-4)
    fine, _ = _sweep(fmu, signals, outs, 1e-8)
    for h in (5.0, 1.0, 0.1, 0.01):
        assert coarse[h] <= 1e-4 * t_max
        assert fine[h] <= coarse[h] / 100.0


def _slave(fmu, work, name):
    md = _description(fmu)
    unzipped = fmpy.extract(fmu, str(work / name))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return s, vr


def _start(s):
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()


def test_bad_values_are_fmi_errors_and_reset_recovers(fmu, work, capfd):
    s, vr = _slave(fmu, work, "bad")
    s.instantiate(loggingOn=True)
    logged = []
    cases = [("input_speed", float("nan"), "NaN"), ("input_speed", -10.0, "input_speed = -10"),
             ("gear", 9, "gear = 9"), ("T_boundary.coolant", float("inf"), "T_boundary.coolant")]
    for name, value, named in cases:
        _start(s)
        s.setReal([vr["input_speed"]], [300.0])
        s.doStep(0.0, 1.0)
        with pytest.raises(fmpy.fmi1.FMICallException) as e:
            if name == "gear":
                s.setInteger([vr[name]], [value])
            else:
                s.setReal([vr[name]], [value])
        assert e.value.status == 3  # fmi2Error
        log = capfd.readouterr().out
        logged.append(f"{name} = {value}: fmi2Error, logged: {log.strip()}")
        assert named in log and "t = 1 s" in log
        s.reset()
        _start(s)
        s.setReal([vr["input_speed"]], [300.0])
        s.doStep(0.0, 1.0)
        assert s.getReal([vr["T.sump"]])[0] > 296.15
        s.reset()
    s.fmi2FreeInstance(s.component)
    with capfd.disabled():
        print("\n" + "\n".join(logged))


def _rss_kb():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS"))


def test_instantiate_reset_free_1000_times_keeps_memory_flat(fmu, work):
    s, vr = _slave(fmu, work, "leak")
    rss = {}
    for i in range(1, 1001):
        s.instantiate()
        _start(s)
        s.setReal([vr["input_speed"], vr["input_torque"]], [300.0, 100.0])
        s.doStep(0.0, 1.0)
        s.reset()
        _start(s)
        s.fmi2FreeInstance(s.component)
        if i in (100, 1000):
            rss[i] = _rss_kb()
    growth = rss[1000] - rss[100]
    print(f"\n1000 x (instantiate, initialise, doStep, reset, free): RSS {rss[100]} kB after 100, "
          f"{rss[1000]} kB after 1000 (+{growth} kB over 900)")
    assert growth < 2048


def test_to_fmu_errors_write_nothing(work):
    m = geartherm.Model.load(AT6)
    out = work / "errors"
    out.mkdir()
    with pytest.raises(geartherm.InputError) as e:
        m.to_fmu(out / "x.fmu", params=["lubrication.no_such_key"])
    assert "lubrication.no_such_key" in str(e.value)
    with pytest.raises(FileNotFoundError):
        m.to_fmu(out / "missing" / "x.fmu")
    with pytest.raises(FileNotFoundError):
        m.to_fmu(out / "x.fmu", runtime=out / "no_runtime.so")
    assert list(out.iterdir()) == []


def test_the_wheels_runtime_is_self_contained():
    """The runtime library the wheel carries needs only the C runtime (no libpython, no other
    library) and exports the FMI 2.0 functions and the model slot."""
    ldd = subprocess.run(["ldd", str(RUNTIME)], check=True, capture_output=True, text=True).stdout
    libs = sorted({line.split()[0] for line in ldd.splitlines() if line.strip()})
    allowed = ("linux-vdso.so", "libc.so", "libm.so", "libgcc_s.so", "ld-linux", "/lib64/ld-linux")
    nm = subprocess.run(["nm", "-D", "--defined-only", str(RUNTIME)], check=True, capture_output=True,
                        text=True).stdout
    exported = sorted(line.split()[-1] for line in nm.splitlines() if line.strip())
    fmi = [x for x in exported if x.startswith("fmi2")]
    print(f"\n{RUNTIME.name}: {RUNTIME.stat().st_size} bytes; needs {libs}; exports {len(fmi)} fmi2 functions "
          f"and {[x for x in exported if not x.startswith('fmi2')]}")
    assert all(lib.startswith(allowed) for lib in libs), libs
    assert len(fmi) == 34 and "fmi2DoStep" in fmi and "fmi2Instantiate" in fmi
    assert [x for x in exported if not x.startswith("fmi2")] == ["MODEL_SLOT"]


def test_a_tunable_parameter_changed_between_steps_equals_two_segments(work):
    """`param.KEYPATH` is tunable: the oil level raised by 20 mm at 300 s in one instance gives,
    over 300-900 s, the temperatures of a second instance started at 300 s from the first's
    temperatures with the new level (within the tolerance; the two integrators take their own
    steps), and differs from the unchanged run by far more; a refused value is an FMI error."""
    path = geartherm.Model.load(AT6).to_fmu(work / "at6_param.fmu", params=["lubrication.oil_level_mm"])
    problems = validate_fmu(path)
    md = _description(path)
    param = next(v for v in md.modelVariables if v.name == "param.lubrication.oil_level_mm")
    assert param.variability == "tunable" and problems == []
    level = float(param.start)
    nodes = [f"T.{n}" for n in _nodes(md)]

    def instance(name, start, level, initial=None):
        s, vr = _slave(path, work, name)
        s.instantiate()
        s.setupExperiment(startTime=start)
        s.setReal([vr["rtol"], vr[param.name]], [1e-8, level])
        for n, t in (initial or {}).items():
            s.setReal([vr[f"T_initial.{n[2:]}"]], [t])
        s.enterInitializationMode()
        s.exitInitializationMode()
        s.setReal([vr["input_speed"], vr["input_torque"]], [300.0, 100.0])
        s.setInteger([vr["gear"]], [2])
        return s, vr

    a, vr = instance("tuned", 0.0, level)
    same, _ = instance("same", 0.0, level)
    for k in range(300):
        a.doStep(float(k), 1.0)
        same.doStep(float(k), 1.0)
    at_300 = dict(zip(nodes, a.getReal([vr[n] for n in nodes])))
    a.setReal([vr[param.name]], [level + 20.0])
    b, _ = instance("two_segments", 300.0, level + 20.0, at_300)
    d_ab = d_same = 0.0
    for k in range(300, 900):
        for s in (a, b, same):
            s.doStep(float(k), 1.0)
        ta, tb, ts = (np.array(s.getReal([vr[n] for n in nodes])) for s in (a, b, same))
        d_ab = max(d_ab, float(np.max(np.abs(ta - tb))))
        d_same = max(d_same, float(np.max(np.abs(ta - ts))))
    print(f"\noil level {level} -> {level + 20} mm at 300 s (FMPy FMU2Slave, rtol 1e-8), 300-900 s: "
          f"max |T(one instance) - T(two segments)| = {d_ab:.3e} K; the change moves T by up to {d_same:.3e} K")
    assert d_same > 1e-2
    assert d_ab <= 1e-6
    with pytest.raises(fmpy.fmi1.FMICallException) as e:
        a.setReal([vr[param.name]], [1e6])
    assert e.value.status == 3
    for s in (a, b, same):
        s.fmi2FreeInstance(s.component)
