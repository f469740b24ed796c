"""geartherm: gearbox power losses and temperatures over drive cycles, from Python.

>>> import geartherm
>>> m = geartherm.Model.load("models/at6_lepelletier.toml")
>>> r = m.override({"lubrication.oil_level_mm": 50}).run(cycle="wltc")
>>> r.timeseries[["time_s", "temp_sump_c"]].tail()
>>> r.summary["energy_lost_j"]["total"]

Time series and maps are pandas DataFrames whose column names carry their units
(``temp_sump_c``, ``loss_churning_s1_sun_w``, ``time_s``); summaries are dicts. Errors are
:class:`GearthermError` subclasses; :class:`ModelError` carries the key path (``.path``) and every
problem (``.problems``: (path, value, allowed) tuples). Every solve releases the GIL. Models and
results pickle (their state travels as JSON), so multiprocessing, Dask and Ray can ship them.

:func:`study` runs a design study on this machine's cores, or on a Dask cluster when given a
``distributed.Client``.
"""

from __future__ import annotations

import io
import json
import math
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

from . import _native
from ._native import GearthermError, InputError, ModelError, SolveError

__all__ = [
    "Model",
    "RunResult",
    "study",
    "study_commands",
    "toml_value",
    "GearthermError",
    "ModelError",
    "InputError",
    "SolveError",
]

__version__ = _native.version()

# The errors are defined in the native module; named as this package's, they pickle (through a
# process pool, to a Dask worker and back) and unpickle as the same class, with their key path.
for _e in (GearthermError, ModelError, InputError, SolveError):
    _e.__module__ = __name__


def toml_value(v: Any) -> str:
    """A Python value as TOML value text (numbers, strings, booleans, lists, dicts)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"{v!r}: model values must be finite")
        return repr(float(v))  # float(): numpy's float64 repr is np.float64(...)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, Iterable):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if hasattr(v, "item"):  # numpy scalars
        return toml_value(v.item())
    raise TypeError(f"{v!r}: cannot be written as a TOML value")


def _frame(csv_text: str):
    import pandas as pd

    # Numbers must come back exactly as written (shortest round-trip form): pandas < 3 needs
    # float_precision="round_trip" for that; from pandas 3 it is the default (and the option is
    # deprecated).
    if int(pd.__version__.split(".")[0]) < 3:
        return pd.read_csv(io.StringIO(csv_text), float_precision="round_trip")
    return pd.read_csv(io.StringIO(csv_text))


class RunResult:
    """A drive-cycle run: ``summary`` (dict, the ``summary.json`` contents) and ``timeseries``
    (pandas DataFrame, the ``timeseries.csv`` columns with units in their names; None when run
    with ``summary_only=True``)."""

    def __init__(self, summary_json: str, timeseries_csv: Optional[str]):
        self._summary_json = summary_json
        self._csv = timeseries_csv
        self.summary: Dict[str, Any] = json.loads(summary_json)
        self._frame = None

    @property
    def timeseries(self):
        if self._csv is None:
            return None
        if self._frame is None:
            self._frame = _frame(self._csv)
        return self._frame

    def __reduce__(self):
        return (RunResult, (self._summary_json, self._csv))

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"RunResult({s.get('model')!r} over {s.get('cycle')!r}: "
            f"{s['energy_lost_j']['total'] / 1e3:.1f} kJ lost)"
        )


class Model:
    """A checked gearbox model (immutable: :meth:`override` returns a new one)."""

    def __init__(self, native: "_native.Model"):
        self._m = native

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Model":
        """Read and check a model file (raises :class:`ModelError` listing every problem)."""
        return cls(_native.Model.load(os.fspath(path)))

    @classmethod
    def from_text(cls, text: str, name: str = "model.toml") -> "Model":
        """Check model text; ``name`` appears in messages."""
        return cls(_native.Model.from_text(text, name))

    def override(self, values: Mapping[str, Any]) -> "Model":
        """A new model with values overridden by key path, e.g.
        ``{"lubrication.oil_level_mm": 55, 'thermal.coolers["atf_cooler"].effectiveness': 0.8}``;
        checked exactly like the file (a :class:`ModelError` names the path and the override)."""
        if not isinstance(values, Mapping):
            raise TypeError(f"override(): values must be a mapping of key path to value, not {type(values).__name__}")
        return Model(self._m.with_overrides([f"{k} = {toml_value(v)}" for k, v in values.items()]))

    @property
    def name(self) -> str:
        return self._m.name

    @property
    def text(self) -> str:
        """The base model's TOML text (without the overrides)."""
        return self._m.text

    @property
    def overrides(self) -> List[str]:
        return list(self._m.overrides)

    def check(self) -> Dict[str, Any]:
        """Counts of the checked model (gears, meshes, gear states, thermal nodes)."""
        return json.loads(self._m.check())

    def info(self) -> Dict[str, Any]:
        """Gear states, ratios, member speeds, meshes, immersion (``geartherm info --json``)."""
        return json.loads(self._m.info())

    def losses(self, gear: str, speed_rpm: float, torque_nm: float, oil_temp_c: float) -> Dict[str, Any]:
        """Every loss item at one operating point (``geartherm losses --json``)."""
        o = {"gear": str(gear), "speed_rpm": float(speed_rpm), "torque_nm": float(torque_nm), "oil_temp_c": float(oil_temp_c)}
        return json.loads(self._m.losses(o))

    def steady(
        self,
        gear: str,
        speed_rpm: float,
        torque_nm: float,
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
    ) -> Dict[str, Any]:
        """Equilibrium temperatures (°C), losses (W) and efficiency at one operating point."""
        p = _point(gear, speed_rpm, torque_nm, vehicle_speed_kmh, ambient_c)
        return json.loads(self._m.steady(p))

    def map(
        self,
        gear: str,
        speed_rpm: Sequence[float],
        torque_nm: Sequence[float],
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
    ):
        """Equilibria over speed × torque (``map.csv`` as a DataFrame), as ``geartherm map``: a
        point without an equilibrium fails the whole map (:class:`SolveError` naming it)."""
        o = {
            "gear": str(gear),
            "speed_rpm": [float(s) for s in speed_rpm],
            "torque_nm": [float(t) for t in torque_nm],
            "vehicle_speed_kmh": float(vehicle_speed_kmh),
            "ambient_c": None if ambient_c is None else float(ambient_c),
        }
        return _frame(self._m.map(o))

    def rating(
        self,
        gear: str,
        speed_rpm: Union[float, Sequence[float]],
        oil_limit_c: float,
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
        torque_min_nm: float = 0.0,
        torque_max_nm: Optional[float] = None,
    ) -> Dict[str, Any]:
        """Thermal rating, as ``geartherm rating``: at each input speed the highest input torque
        whose equilibrium oil temperature stays at or below ``oil_limit_c`` (the ``rating.json``
        document as a dict: ``points`` with ``rated_torque_nm``, ``rated_power_w``, ``status``, the
        equilibrium at that torque)."""
        speeds = [float(speed_rpm)] if isinstance(speed_rpm, (int, float)) else [float(s) for s in speed_rpm]
        o = {
            "gear": str(gear),
            "speed_rpm": speeds,
            "oil_limit_c": float(oil_limit_c),
            "vehicle_speed_kmh": float(vehicle_speed_kmh),
            "ambient_c": None if ambient_c is None else float(ambient_c),
            "torque_min_nm": float(torque_min_nm),
            "torque_max_nm": None if torque_max_nm is None else float(torque_max_nm),
        }
        return json.loads(self._m.rating(o))

    def run(
        self,
        cycle: str = "wltc",
        *,
        solver: str = "auto",
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        initial_temp_c: Optional[float] = None,
        ambient_c: Optional[float] = None,
        max_steps: Optional[int] = None,
        summary_only: bool = False,
        frozen_viscosity_c: Optional[float] = None,
        evaluate_all: bool = False,
    ) -> RunResult:
        """A drive-cycle transient (bundled cycle name or CSV file), as ``geartherm run``."""
        o: Dict[str, Any] = {
            "cycle": os.fspath(cycle),
            "solver": solver,
            "summary_only": bool(summary_only),
            "evaluate_all": bool(evaluate_all),
            "frozen_viscosity_c": None if frozen_viscosity_c is None else float(frozen_viscosity_c),
        }
        for k, v in (("rtol", rtol), ("atol", atol), ("max_steps", max_steps)):
            if v is not None:
                o[k] = v
        o["initial_temp_c"] = initial_temp_c
        o["ambient_c"] = ambient_c
        summary, csv = self._m.run(o)
        return RunResult(summary, csv)

    def __reduce__(self):
        return (Model, (self._m,))

    def __repr__(self) -> str:
        return repr(self._m)


def _point(gear, speed_rpm, torque_nm, vehicle_speed_kmh, ambient_c) -> Dict[str, Any]:
    return {
        "gear": str(gear),
        "speed_rpm": float(speed_rpm),
        "torque_nm": float(torque_nm),
        "vehicle_speed_kmh": float(vehicle_speed_kmh),
        "ambient_c": None if ambient_c is None else float(ambient_c),
    }


# ---------------------------------------------------------------------------------------------
# Studies


def _spec(
    parameters,
    job: Optional[Mapping[str, Any]],
    sampling: Optional[Mapping[str, Any]],
    name: str,
) -> Dict[str, Any]:
    if isinstance(parameters, Mapping) and all(isinstance(s, Mapping) for s in parameters.values()):
        params = [dict(spec, path=path) for path, spec in parameters.items()]
    elif isinstance(parameters, (list, tuple)) and all(isinstance(p, Mapping) for p in parameters):
        params = [dict(p) for p in parameters]
    else:
        raise TypeError(
            "study(): parameters must be a mapping {key path: {\"range\" | \"values\" | \"scale\": ...}} "
            f"or a list of such mappings with a \"path\", not {type(parameters).__name__}"
        )
    return {
        "study": {"name": name, "model": ""},
        "job": dict(job) if job is not None else {"kind": "run", "cycles": ["wltc"]},
        "sampling": dict(sampling) if sampling is not None else {"plan": "grid"},
        "parameters": params,
        "outputs": {},
    }


def _batch(spec_json: str, text: str, file: str, indices: List[int], threads: Optional[int]) -> str:
    """One Dask task: solve a batch of cases from the shipped study and model text."""
    return _native.run_cases(spec_json, text, file, indices, threads)


def _rows_to_frame(rows: List[Dict[str, Any]]):
    import pandas as pd

    records = []
    for r in rows:
        rec: Dict[str, Any] = {"case": r["case"], "sample": r["sample"], "job": r["job"]}
        for k, v in r["params"]:
            rec[k] = v
        rec["status"] = r["status"]
        rec["message"] = r["message"]
        for k, v in r["outputs"]:
            rec[k] = math.nan if v is None else v
        records.append(rec)
    return pd.DataFrame.from_records(records)


def _case_indices(cases, n: int) -> List[int]:
    """`cases` as distinct positions in [0, n), each once (a case run twice would be two rows)."""
    import operator

    todo = [operator.index(i) for i in cases]
    for i in todo:
        if not 0 <= i < n:
            raise InputError(f"cases: {i}: must lie in [0, {n}) (the study has {n} cases)")
    if len(set(todo)) != len(todo):
        raise InputError("cases: a case is given more than once; each case runs once")
    return todo


def study(
    model: Union[Model, str, os.PathLike],
    parameters: Union[Mapping[str, Mapping[str, Any]], Sequence[Mapping[str, Any]]],
    job: Optional[Mapping[str, Any]] = None,
    sampling: Optional[Mapping[str, Any]] = None,
    *,
    client=None,
    batch_size: Optional[int] = None,
    threads_per_task: Optional[int] = None,
    cases: Optional[Sequence[int]] = None,
    name: str = "study",
):
    """Run a design study and return one DataFrame row per case.

    ``parameters``: ``{key_path: {"range": [lo, hi]} | {"values": [...]} | {"scale": [lo, hi]}}``
    (``"levels": n`` for grid points of a range). ``job``: ``{"kind": "run", "cycles": ["wltc"]}``
    (default), ``{"kind": "steady", "points": [{"gear": "3", "speed_rpm": 2000, "torque_nm":
    100}]}`` or ``{"kind": "map", "gear": "3", "speed_rpm": [...], "torque_nm": [...]}``.
    ``sampling``: ``{"plan": "grid"}`` (default), ``{"plan": "lhs", "cases": 1000, "seed": 7}``
    or ``{"plan": "list"}``. The same structure as a study file (``geartherm study``).

    Without ``client`` the cases run on this machine's cores (rayon, GIL released). With a
    ``distributed.Client`` the cases are cut into batches (``batch_size``, default about four
    batches per worker thread), each batch is one task carrying the study and the model *text*
    (nothing is read from the workers' disks), and the rows are gathered into one DataFrame in
    case order. ``cases`` restricts the run to these positions in the study's case list (e.g.
    to rerun failed cases, or to share a plan between machines). A failing case is a row with ``status`` ``failed`` or ``invalid`` and its
    ``message``; it does not stop the study.
    """
    if not isinstance(model, Model):
        model = Model.load(model)
    if model.overrides:
        raise InputError("study(): pass the base model without overrides; vary values through parameters")
    spec_json = json.dumps(_spec(parameters, job, sampling, name))
    text, file = model.text, model._m.file
    _, ids = _native.study_cases(spec_json, text, file)
    todo = list(range(len(ids))) if cases is None else _case_indices(cases, len(ids))
    n = len(todo)
    if client is None:
        rows = json.loads(_native.run_cases(spec_json, text, file, todo, threads_per_task))
    else:
        if batch_size is None:
            workers = sum(client.nthreads().values()) or 1
            batch_size = max(1, math.ceil(n / (4 * workers)))
        batches = [todo[i : i + batch_size] for i in range(0, n, batch_size)]
        futures = client.map(
            _batch,
            [spec_json] * len(batches),
            [text] * len(batches),
            [file] * len(batches),
            batches,
            [threads_per_task] * len(batches),
            pure=False,
        )
        rows = []
        for part in client.gather(futures):
            rows.extend(json.loads(part))
    return _rows_to_frame(rows)


def study_commands(
    model: Union[Model, str, os.PathLike],
    parameters,
    job: Optional[Mapping[str, Any]] = None,
    sampling: Optional[Mapping[str, Any]] = None,
) -> List[str]:
    """The stand-alone ``geartherm run``/``steady`` command line of every case (for Slurm
    arrays or HyperQueue without Python)."""
    if not isinstance(model, Model):
        model = Model.load(model)
    spec_json = json.dumps(_spec(parameters, job, sampling, "study"))
    return _native.study_commands(spec_json, model.text, model._m.file)
