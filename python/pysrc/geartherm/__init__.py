"""geartherm: gearbox power losses and temperatures over drive cycles, from Python.

>>> import geartherm
>>> m = geartherm.Model.load("models/at6_lepelletier.toml")
>>> r = m.override({"lubrication.oil_level_mm": 50}).run(cycle="hwfet")
>>> float(r.timeseries["temp_sump_c"].iloc[-1]) > 23
True

Time series and maps are pandas DataFrames whose column names carry their units
(``temp_sump_c``, ``loss_churning_w``, ``loss_churning_s1_sun_w``, ``time_s``; docs/outputs.md);
summaries are dicts. Errors are :class:`GearthermError` subclasses (:class:`ModelError` and
:class:`InputError` are also :class:`ValueError`) carrying the key path (``.path``), the value
and the allowed range, and they pickle with those fields; a missing file is
:class:`FileNotFoundError`. Range warnings are :class:`RangeWarning` warnings. Every solve
releases the GIL. Models and results pickle, so multiprocessing, Dask and Ray can ship them.

:func:`study` runs a design study (the runner of ``geartherm study``: progress, Ctrl-C, journal,
resume, the same files) on this machine's cores, or on a Dask cluster given a
``distributed.Client``. :func:`oils` and :func:`cycles` list the catalogue oils and the bundled
drive cycles; :func:`read_run` and :func:`read_study` read result directories back.
"""

from __future__ import annotations

import json
import math
import os
from typing import TYPE_CHECKING, Dict, Iterable, List, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

from . import _cli, _native
from ._tables import frame as _frame
from ._tables import html_table as _html_table
from ._tables import warn_ranges as _warn_ranges
from ._types import CycleLike, Json, PathLike, TomlValue
from .calibration import CalibrationResult, TraceFile, read_trace
from .calibration import _trace_text
from .errors import GearthermError, InputError, ModelError, RangeWarning, SolveError
from .results import RunResult, RunSummary, read_run
from .study import Study, read_study, study, study_commands

if TYPE_CHECKING:
    import distributed
    import pandas
    import polars

    from .uq import UqResult

__all__ = [
    "CalibrationResult",
    "Model",
    "RunResult",
    "RunSummary",
    "TraceFile",
    "read_trace",
    "Study",
    "study",
    "study_commands",
    "read_run",
    "read_study",
    "oils",
    "cycles",
    "toml_value",
    "SOURCES",
    "GearthermError",
    "ModelError",
    "InputError",
    "SolveError",
    "RangeWarning",
]

__version__ = _native.version()

#: The loss sources, in the order of every per-source column and key.
SOURCES = tuple(_native.sources())

#: Solvers of :meth:`Model.run`.
SOLVERS = ("auto", "ros3", "tr-bdf2", "esdirk34", "bdf", "tsit45")


def toml_value(v: TomlValue) -> str:
    """A Python value as TOML value text.

    Parameters
    ----------
    v : bool, int, float, str, mapping, iterable or numpy scalar

    Returns
    -------
    str
        ``"true"``, ``"40"``, ``"0.5"``, ``'"fva_3a"'``, ``"[1, 2]"``, ``'{"a" = 1}'``.

    Raises
    ------
    ValueError
        A non-finite float (a model value must be finite).
    TypeError
        A value TOML cannot hold.
    """
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
        return toml_value(v.item())  # type: ignore[union-attr]
    raise TypeError(f"{v!r}: cannot be written as a TOML value")


def oils() -> "pandas.DataFrame":
    """The oil catalogue (``models/oils.toml``, compiled in) as a DataFrame.

    Returns
    -------
    pandas.DataFrame
        One row per oil: ``key`` (the value of ``oil.catalogue``), ``name``, ``nu40_cst`` and
        ``nu100_cst`` (kinematic viscosity at 40 and 100 °C, cSt), ``rho15_kg_m3`` (density at
        15 °C), ``thermal_expansion_per_k``, ``density_assumed``, ``base`` (base stock),
        ``lubricant_factor`` (X_L, None where the oil has none measured), ``source``.
    """
    import pandas as pd

    return pd.DataFrame.from_records(json.loads(_native.oils()))


def cycles() -> "pandas.DataFrame":
    """The bundled drive cycles as a DataFrame.

    Returns
    -------
    pandas.DataFrame
        One row per cycle: ``name`` (the value of ``Model.run(cycle=...)``), ``duration_s``,
        ``distance_km``, ``max_speed_kmh``, ``segments``.
    """
    import pandas as pd

    return pd.DataFrame.from_records(json.loads(_native.cycles()))


def _cycle_options(cycle: CycleLike) -> Dict[str, object]:
    """A cycle name or CSV path as ``cycle``; a DataFrame (pandas or polars, its columns as they
    are: ``time_s`` and ``speed_kmh``, or a rig cycle's columns) as CSV text in ``cycle_text``,
    named ``DataFrame`` in messages and the summary."""
    if isinstance(cycle, (str, os.PathLike)):
        return {"cycle": os.fspath(cycle)}
    if hasattr(cycle, "to_csv"):
        return {"cycle": "DataFrame", "cycle_text": cycle.to_csv(index=False)}
    return {"cycle": "DataFrame", "cycle_text": cycle.write_csv()}  # polars




class Model:
    """A checked gearbox model (immutable: :meth:`override` returns a new one).

    Build one with :meth:`load` (a model file) or :meth:`from_text`. Every method solves on the
    native library with the GIL released; a Model pickles as its text, file name and overrides
    and is checked again on arrival.
    """

    def __init__(self, native: "_native.Model"):
        self._m = native

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "Model":
        """Read and check a model file (docs/model-file.md).

        Parameters
        ----------
        path : str or path-like
            The model's TOML file.

        Raises
        ------
        FileNotFoundError
            No such file (``.filename`` is the path).
        ModelError
            An invalid model; ``.problems`` lists every problem as (key path, value, allowed).
        """
        return cls(_native.Model.load(os.fspath(path)))

    @classmethod
    def from_text(cls, text: str, name: str = "model.toml") -> "Model":
        """Check model text; ``name`` is the file name its messages show.

        Raises
        ------
        ModelError
            An invalid model.
        """
        return cls(_native.Model.from_text(text, name))

    def override(self, values: Mapping[str, TomlValue]) -> "Model":
        """A new model with values overridden by key path, checked exactly like the file.

        Parameters
        ----------
        values : mapping of key path to value
            e.g. ``{"lubrication.oil_level_mm": 55, "oil.catalogue": "fva_3a",
            'thermal.coolers["atf_cooler"].effectiveness': 0.8}``; an array entry is named by
            index (``gears[2].teeth``) or by its name (``coolers["atf_cooler"]``).

        Raises
        ------
        ModelError
            An unknown path or an invalid value (``.path``, ``.value``, ``.allowed``).
        """
        if not isinstance(values, Mapping):
            raise TypeError(f"override(): values must be a mapping of key path to value, not {type(values).__name__}")
        return Model(self._m.with_overrides([f"{k} = {toml_value(v)}" for k, v in values.items()]))

    @property
    def name(self) -> str:
        """The model's name (``[model] name``)."""
        return self._m.name

    @property
    def file(self) -> str:
        """The file name messages show."""
        return self._m.file

    @property
    def text(self) -> str:
        """The base model's TOML text (without the overrides)."""
        return self._m.text

    @property
    def overrides(self) -> List[str]:
        """The overrides applied, as ``"path = toml value"`` lines."""
        return list(self._m.overrides)

    def to_toml(self) -> str:
        """The model as TOML text with every override written in at its key path (the base
        file's comments and layout kept): ``Model.from_text(m.to_toml())`` is equal to ``m``,
        and ``geartherm check`` accepts the text as a model file."""
        return self._m.to_toml()

    def to_fmu(
        self,
        path: PathLike,
        params: Sequence[str] = (),
        runtime: Optional[PathLike] = None,
    ) -> str:
        """Export the model as an FMI 2.0 co-simulation FMU (as ``geartherm fmu``; docs/fmu.md).

        Parameters
        ----------
        path : str or path-like
            The FMU to write, ``NAME.fmu`` (NAME, made a C identifier, is the model identifier).
            Written to a temporary file and renamed: nothing is written on error.
        params : sequence of str
            Key paths exported as FMU parameters (checked as ``--set``: each must exist and hold
            a number).
        runtime : str or path-like, optional
            The runtime library ``libgeartherm_fmu.so`` to put into the FMU; default
            ``$GEARTHERM_FMU_RUNTIME`` when set, else the one the wheel carries
            (``geartherm/_bin/libgeartherm_fmu.so``, built with the package).

        Returns
        -------
        str
            The path written.

        Raises
        ------
        ModelError, InputError
            The model or a parameter key path does not check.
        OSError
            No runtime library, or the FMU cannot be written.
        """
        if runtime is None:
            runtime = os.environ.get("GEARTHERM_FMU_RUNTIME") or _cli.BIN_DIR / "libgeartherm_fmu.so"
        return _native.export_fmu(self._m, os.fspath(path), list(params), os.fspath(runtime))

    def __eq__(self, other: object) -> bool:
        """Equal when the checked models are: every value bit for bit, whatever text, file name
        and overrides made them."""
        if not isinstance(other, Model):
            return NotImplemented
        return bool(self._m == other._m)

    __hash__ = None  # type: ignore[assignment]

    def check(self) -> Dict[str, Json]:
        """Counts of the checked model.

        Returns
        -------
        dict
            ``model``, ``gears``, ``meshes``, ``gear_states`` (names), ``thermal_nodes``,
            ``vehicle`` (bool).
        """
        return json.loads(self._m.check())

    def info(self) -> Dict[str, Json]:
        """Gear states, ratios, member speeds, meshes and immersion (``geartherm info --json``)."""
        return json.loads(self._m.info())

    @overload
    def losses(
        self, gear: str, speed_rpm: float, torque_nm: float, oil_temp_c: float, *, output: Literal["frame"] = ...
    ) -> "pandas.DataFrame": ...
    @overload
    def losses(
        self, gear: str, speed_rpm: float, torque_nm: float, oil_temp_c: float, *, output: Literal["dict"]
    ) -> Dict[str, Json]: ...
    def losses(
        self,
        gear: str,
        speed_rpm: float,
        torque_nm: float,
        oil_temp_c: float,
        *,
        output: Literal["frame", "dict"] = "frame",
    ) -> Union["pandas.DataFrame", Dict[str, Json]]:
        """Every loss item at one operating point and oil temperature (``geartherm losses``).

        Parameters
        ----------
        gear : str
            Gear-state name (``"1"`` … ``"6"``, ``"R"``; see ``check()["gear_states"]``).
        speed_rpm : float
            Input speed, rpm.
        torque_nm : float
            Input torque, N·m.
        oil_temp_c : float
            Oil temperature, °C.
        output : {"frame", "dict"}, default "frame"
            ``"frame"``: a DataFrame with one row per loss item (``source``, ``name``, ``w``);
            its ``attrs`` hold the rest of the report. ``"dict"``: the ``geartherm losses
            --json`` report: ``loss_<source>_w`` per source and ``loss_total_w`` (W),
            ``items``, ``efficiency``, the oil's viscosity and density at that temperature,
            ``skipped``, ``warnings``, ``spread`` (the model-form spread: every applicable
            model of each item's source, docs/uq.md).

        Range warnings are raised as one :class:`RangeWarning` (a one-line summary).

        Raises
        ------
        InputError
            An unknown gear or an option out of its range.
        """
        o = {"gear": str(gear), "speed_rpm": float(speed_rpm), "torque_nm": float(torque_nm), "oil_temp_c": float(oil_temp_c)}
        r = json.loads(self._m.losses(o))
        _warn_ranges(r.get("warnings"))
        return _as_frame(r, r.get("items", []), output)

    @overload
    def steady(
        self,
        gear: str,
        speed_rpm: float,
        torque_nm: float,
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        *,
        output: Literal["frame"] = ...,
    ) -> "pandas.DataFrame": ...
    @overload
    def steady(
        self,
        gear: str,
        speed_rpm: float,
        torque_nm: float,
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        *,
        output: Literal["dict"],
    ) -> Dict[str, Json]: ...
    def steady(
        self,
        gear: str,
        speed_rpm: float,
        torque_nm: float,
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
        *,
        output: Literal["frame", "dict"] = "frame",
    ) -> Union["pandas.DataFrame", Dict[str, Json]]:
        """The thermal equilibrium at one operating point (``geartherm steady``).

        Parameters
        ----------
        gear : str
            Gear-state name.
        speed_rpm, torque_nm : float
            Input speed (rpm) and torque (N·m).
        vehicle_speed_kmh : float, default 0
            Vehicle speed for the speed-dependent heat transfer h(v), km/h.
        ambient_c : float, optional
            Ambient temperature, °C (default: the model's).
        output : {"frame", "dict"}, default "frame"
            ``"frame"``: a one-row DataFrame with every number of the report
            (``loss_<source>_w``, ``loss_total_w``, ``efficiency``, ``iterations``, …) and
            ``temp_<node>_c`` per node (the columns of a map row); its ``attrs`` hold the
            whole report. ``"dict"``: the report: ``temperatures_c`` (per node, °C),
            ``loss_<source>_w`` per source and ``loss_total_w`` (W), ``losses_w`` per item,
            ``efficiency``, the Newton iterations, ``warnings``.

        Raises
        ------
        InputError
            An unknown gear or an option out of its range.
        SolveError
            No equilibrium (the message says why).
        """
        p = _point(gear, speed_rpm, torque_nm, vehicle_speed_kmh, ambient_c)
        r = json.loads(self._m.steady(p))
        _warn_ranges(r.get("warnings"))
        return _as_frame(r, [_steady_row(r)], output)

    @overload
    def map(
        self,
        gear: str,
        speed_rpm: Sequence[float],
        torque_nm: Sequence[float],
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        *,
        backend: Literal["pandas"] = ...,
    ) -> "pandas.DataFrame": ...
    @overload
    def map(
        self,
        gear: str,
        speed_rpm: Sequence[float],
        torque_nm: Sequence[float],
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        *,
        backend: Literal["polars"],
    ) -> "polars.DataFrame": ...
    def map(
        self,
        gear: str,
        speed_rpm: Sequence[float],
        torque_nm: Sequence[float],
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
        *,
        backend: Literal["pandas", "polars"] = "pandas",
    ) -> Union["pandas.DataFrame", "polars.DataFrame"]:
        """Equilibria over a speed × torque grid (``geartherm map``).

        Parameters
        ----------
        gear : str
            Gear-state name.
        speed_rpm, torque_nm : sequence of float
            The grid's input speeds (rpm) and torques (N·m).
        vehicle_speed_kmh, ambient_c : float
            As in :meth:`steady`.
        backend : {"pandas", "polars"}

        Returns
        -------
        DataFrame
            ``map.csv``: ``speed_rpm``, ``torque_nm``, ``efficiency``, ``loss_total_w``,
            ``loss_<source>_w``, ``oil_temp_c``, ``iterations``, ``converged`` (float64 for
            every quantity).

        Raises
        ------
        SolveError
            A point without an equilibrium fails the whole map, naming it.
        """
        o = {
            "gear": str(gear),
            "speed_rpm": [float(s) for s in speed_rpm],
            "torque_nm": [float(t) for t in torque_nm],
            "vehicle_speed_kmh": float(vehicle_speed_kmh),
            "ambient_c": None if ambient_c is None else float(ambient_c),
        }
        return _frame(self._m.map(o), backend=backend)

    @overload
    def rating(
        self,
        gear: str,
        speed_rpm: Union[float, Sequence[float]],
        oil_limit_c: float,
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        torque_min_nm: float = ...,
        torque_max_nm: Optional[float] = ...,
        *,
        output: Literal["frame"] = ...,
    ) -> "pandas.DataFrame": ...
    @overload
    def rating(
        self,
        gear: str,
        speed_rpm: Union[float, Sequence[float]],
        oil_limit_c: float,
        vehicle_speed_kmh: float = ...,
        ambient_c: Optional[float] = ...,
        torque_min_nm: float = ...,
        torque_max_nm: Optional[float] = ...,
        *,
        output: Literal["dict"],
    ) -> Dict[str, Json]: ...
    def rating(
        self,
        gear: str,
        speed_rpm: Union[float, Sequence[float]],
        oil_limit_c: float,
        vehicle_speed_kmh: float = 0.0,
        ambient_c: Optional[float] = None,
        torque_min_nm: float = 0.0,
        torque_max_nm: Optional[float] = None,
        *,
        output: Literal["frame", "dict"] = "frame",
    ) -> Union["pandas.DataFrame", Dict[str, Json]]:
        """Thermal rating, as ``geartherm rating``: at each input speed the highest input torque
        whose equilibrium oil temperature stays at or below ``oil_limit_c``.

        Parameters
        ----------
        gear : str
            Gear-state name.
        speed_rpm : float or sequence of float
            Input speed(s), rpm, 0 … 50 000 (a sequence gives the rating curve).
        oil_limit_c : float
            Oil temperature limit, °C, −60 … 200.
        vehicle_speed_kmh, ambient_c : float
            As in :meth:`steady`.
        torque_min_nm : float, default 0
            Lowest torque searched, N·m.
        torque_max_nm : float, optional
            The ceiling, N·m (default 1e6: a model states no torque capacity).

        output : {"frame", "dict"}, default "frame"
            ``"frame"``: one row per speed with the numbers and flags of each point
            (``speed_rpm``, ``rated_torque_nm``, ``rated_power_w``, ``oil_temp_c``,
            ``loss_total_w``, ``efficiency``, ``status``, ``non_monotonic``); its ``attrs``
            hold the whole document. ``"dict"``: the ``rating.json`` document: ``points`` with ``speed_rpm``, ``rated_torque_nm``,
            ``rated_power_w``, ``oil_temp_c``, ``loss_total_w``, ``efficiency``, ``status``,
            ``non_monotonic`` and the ``equilibrium`` at that torque (the :meth:`steady` dict);
            ``warnings`` (each also raised as a :class:`RangeWarning`).

        Raises
        ------
        InputError
            An unknown gear or an option out of its range.
        SolveError
            No equilibrium at the lowest torque, or a jump across the limit.
        """
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
        r = json.loads(self._m.rating(o))
        _warn_ranges(r.get("warnings"))
        return _as_frame(r, [_scalars(p) for p in r.get("points", [])], output)

    def run(
        self,
        cycle: CycleLike = "wltc",
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
        spread: bool = False,
    ) -> RunResult:
        """A drive-cycle transient (``geartherm run``).

        Parameters
        ----------
        cycle : str, path or DataFrame, default "wltc"
            A bundled cycle (:func:`cycles` lists them), a CSV file, or a DataFrame with the
            CSV's columns (``time_s``, ``speed_kmh``; or a rig cycle's ``time_s``, ``gear``,
            ``input_speed_rpm``, ``input_torque_nm``).
        solver : {"auto", "ros3", "tr-bdf2", "esdirk34", "bdf", "tsit45"}, default "auto"
            ``auto`` is ROS3 up to 24 capacity nodes, TR-BDF2 above (docs/numerics.md).
        rtol : float, default 1e-4
            Relative tolerance, in [1e-14, 0.1].
        atol : float, default 1e-6
            Absolute tolerance on temperatures, K, in [1e-14, 1].
        initial_temp_c : float, optional
            Initial temperature of every node, °C (default: the model's).
        ambient_c : float, optional
            Ambient temperature, °C (default: the model's ambient boundary).
        max_steps : int, default 5 000 000
            Step budget; the run fails beyond it.
        summary_only : bool, default False
            No time series (faster); the summary is complete.
        frozen_viscosity_c : float, optional
            Oil properties frozen at this temperature, °C (viscosity feedback off).
        evaluate_all : bool, default False
            No pruning of unused gear states and idle items (for measuring what it saves).
        spread : bool, default False
            Model-form spread: ``summary["spread"]`` holds, per source, the energy each
            applicable model choice gives along this run's trajectory (docs/uq.md).

        Returns
        -------
        RunResult
            ``summary`` (dict) and ``timeseries`` (DataFrame, None with ``summary_only``);
            each range warning is also raised as a :class:`RangeWarning`.

        Raises
        ------
        InputError
            An unknown cycle or solver, an option out of its range.
        SolveError
            A numerical failure (the message names the time, node or loss item).
        """
        o: Dict[str, object] = {
            **_cycle_options(cycle),
            "solver": solver,
            "summary_only": bool(summary_only),
            "evaluate_all": bool(evaluate_all),
            "spread": bool(spread),
            "frozen_viscosity_c": None if frozen_viscosity_c is None else float(frozen_viscosity_c),
        }
        for k, v in (("rtol", rtol), ("atol", atol), ("max_steps", max_steps)):
            if v is not None:
                o[k] = v
        o["initial_temp_c"] = initial_temp_c
        o["ambient_c"] = ambient_c
        summary, csv = self._m.run(o)
        r = RunResult(summary, csv)
        _warn_ranges(r.summary.get("warnings"))
        return r

    def calibrate(
        self,
        trace: Union[PathLike, "pandas.DataFrame", None] = None,
        fit: Sequence[str] = (),
        holdout: Optional[Sequence[Union[str, Tuple[float, float]]]] = None,
        *,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        max_steps: Optional[int] = None,
        max_iterations: Optional[int] = None,
        initial_from_trace: bool = True,
        segment: Optional[int] = None,
        missing: Literal["drop", "refuse"] = "drop",
        name: Optional[str] = None,
        residuals: Optional[Literal["ar1", "ar1-gls", "independent"]] = None,
        band_quantile: Optional[Literal["empirical", "t"]] = None,
        prior: Union[Mapping[str, Tuple[str, float, float]], Sequence[str]] = (),
        priors_file: Optional[PathLike] = None,
        profile: Sequence[str] = (),
        gearbox_kind: Optional[str] = None,
        rated: Optional[Tuple[float, float]] = None,
        traces: Optional[Sequence[Union[PathLike, "pandas.DataFrame"]]] = None,
        names: Optional[Sequence[str]] = None,
        segments: Optional[str] = None,
        client: Optional[object] = None,
    ) -> CalibrationResult:
        """Fit parameters (``fit``: key paths, ``"KEYPATH=LO:HI"`` with bounds) to a measured
        trace, as ``geartherm calibrate``.

        Parameters
        ----------
        trace : DataFrame or path
            A DataFrame (or a CSV file) with the cycle's columns (``time_s`` and ``speed_kmh``
            or ``input_speed_rpm``, ``input_torque_nm``, ``gear``), ``boundary:NAME`` and
            ``node:NAME`` temperature columns in °C (docs/calibration.md). Rows with an empty
            cell are dropped and counted (listed in the warnings); gaps in time cut it into
            segments (:func:`read_trace` lists them).
        fit : sequence of str
            Key paths, each optionally ``=LO:HI``.
        holdout : sequence of (t0, t1) or "t0:t1"
            Time windows, s, predicted, not fitted.
        segment : int, optional
            The segment fitted (needed when gaps cut the trace into several).
        missing : {"drop", "refuse"}
            ``"refuse"``: an empty cell is an :class:`InputError`.
        rtol, atol, max_steps, max_iterations, initial_from_trace
            As ``geartherm calibrate``'s options.
        name : str, optional
            The trace's name in messages (default: its path, or ``trace``).
        residuals : {"ar1", "ar1-gls", "independent"}, optional
            The residual model (``--residuals``; default ``ar1``).
        band_quantile : {"empirical", "t"}, optional
            The 95 % band's multiplier of its standard deviation (``--band-quantile``; default
            ``empirical``: the fitted rows' own 95 % quantile of |residual|/sd per channel and
            trace, Student's t when they are too few; ``t``: Student's t, Gaussian residuals).
            :attr:`CalibrationResult.errors` has it per channel (``band_multiplier``,
            ``band_quantile``).
        prior : mapping or sequence of str
            Priors (a MAP fit): ``{key_path: ("normal", mean, sd)}`` or
            ``{key_path: ("lognormal", median, sd_ln)}``, or ``--prior`` strings
            ``"KEYPATH=normal:MEAN:SD"``.
        priors_file : path, optional
            A TOML file of ``[[prior]]`` tables (``--priors FILE``).
        profile : sequence of str
            Fitted key paths whose profile likelihood is computed (:attr:`CalibrationResult.profiles`).
        gearbox_kind : str, optional
            ``"wind-turbine"``: compare the calibrated losses with the sourced figure.
        rated : (rpm, N·m), optional
            A rated point at which the calibrated losses are reported.
        traces : sequence of DataFrame or path, optional
            Several traces in one fit (instead of ``trace``; docs/calibration.md, "Several
            traces"): every segment of each; ``fit`` keys ``KEYPATH@N`` (N a trace's index or
            name, ``@*`` one per trace) are a trace's own. :attr:`CalibrationResult.traces`
            has the errors per trace, :attr:`CalibrationResult.fit` the columns ``trace``,
            ``segment`` first.
        names : sequence of str, optional
            The traces' names (default: a path's stem, ``trace<N>`` for a DataFrame).
        segments : str, optional
            ``"all"`` or ``"K1,K2,…"``: several segments of one trace in one fit.
        client : dask.distributed.Client, optional
            With ``traces``: the segments are integrated on the client's workers (the fit's
            steps here).
        """
        if traces is None and segments is None:
            if trace is None:
                raise TypeError("calibrate: give trace (or traces)")
            text, label = _trace_text(trace, name)
        windows = []
        for h in holdout or ():
            windows.append(h if isinstance(h, str) else f"{float(h[0])!r}:{float(h[1])!r}")
        o: Dict[str, object] = {
            "fit": [str(f) for f in fit],
            "holdout": windows,
            "initial_from_trace": bool(initial_from_trace),
            "refuse_missing": missing == "refuse",
        }
        if segment is not None:
            o["segment"] = segment
        priors: List[str] = []
        if priors_file is not None:
            path = os.fspath(priors_file)
            with open(path, encoding="utf-8") as fh:
                priors.extend(_native.priors_from_file(fh.read(), path))
        if isinstance(prior, Mapping):
            for key, (dist, loc, width) in prior.items():
                priors.append(f"{key}={dist}:{float(loc)!r}:{float(width)!r}")
        else:
            priors.extend(str(p) for p in prior)
        o["prior"] = priors
        o["profile"] = [str(k) for k in profile]
        if residuals is not None:
            o["residuals"] = residuals
        if band_quantile is not None:
            o["band_quantile"] = band_quantile
        if gearbox_kind is not None:
            o["gearbox_kind"] = gearbox_kind
        if rated is not None:
            o["rated"] = f"{float(rated[0])!r}:{float(rated[1])!r}"
        for k, v in (("rtol", rtol), ("atol", atol), ("max_steps", max_steps), ("max_iterations", max_iterations)):
            if v is not None:
                o[k] = v
        if traces is not None or segments is not None:
            from .calibration import calibrate_traces

            given = list(traces) if traces is not None else [trace]
            triples = []
            for i, t in enumerate(given):
                default = os.path.splitext(os.path.basename(os.fspath(t)))[0] if isinstance(t, (str, os.PathLike)) else f"trace{i}"
                name_i = names[i] if names is not None else default
                text_i, path_i = _trace_text(t, None)
                label_i = path_i if isinstance(t, (str, os.PathLike)) else name_i
                triples.append((text_i, name_i, label_i))
            if segments is not None:
                o["segments"] = segments
            return calibrate_traces(self._m, triples, o, client)
        return CalibrationResult(*self._m.calibrate(text, label, o))


    def uq(
        self,
        cycle: Optional[str] = None,
        *,
        point: Optional[Mapping[str, object]] = None,
        inputs: Optional[Sequence[Mapping[str, object]]] = None,
        correlations: Optional[Sequence[Mapping[str, object]]] = None,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        sobol: bool = False,
        percentiles: Sequence[float] = (5.0, 50.0, 95.0),
        limits: Optional[Mapping[str, float]] = None,
        series_points: int = 201,
        confidence: float = 0.95,
        bootstrap: int = 200,
        calibration: Optional[Mapping[str, object]] = None,
        out: Optional[Union[str, "os.PathLike[str]"]] = None,
        threads: Optional[int] = None,
        client: Optional["distributed.Client"] = None,
        batch_size: Optional[int] = None,
        threads_per_task: Optional[int] = 1,
    ) -> "UqResult":
        """Uncertainty study: the uncertain inputs sampled quasi-randomly, the cycle (or the
        steady ``point``: ``dict(gear=, speed_rpm=, torque_nm=)``) solved for every sample by the
        study runner, percentile bands, exceedance probabilities of ``limits`` (node → °C) and,
        with ``sobol=True``, Sobol indices (docs/uq.md; the same checks as ``geartherm uq``).

        ``inputs``: dicts as ``[[uncertainty.inputs]]`` (``path``, ``dist``, its parameters,
        ``truncate``, ``relative``, ``note``); None: the model file's ``[uncertainty]``.
        ``out``: a directory journaled as ``geartherm uq --out`` writes it (resume).
        ``client``: a ``distributed.Client``; the samples are solved by Dask tasks of
        ``batch_size`` samples each (default: about four batches per worker thread, each task
        with ``threads_per_task`` threads) through the runner's session held here (the same
        journal and resume as ``Study.run(client=...)``); the estimates are made here, and equal
        the local ones bit for bit.
        The model's overrides are not applied (the model file's text is sampled).

        Returns
        -------
        UqResult
            ``.bands`` (columns per series and percentile), ``.exceedance``, ``.sobol``,
            ``.samples`` DataFrames and ``.summary`` (``uq.json``).
        """
        from .uq import run_uq

        pt = None
        if point is not None:
            p = dict(point)
            pt = _point(str(p["gear"]), float(p["speed_rpm"]), float(p["torque_nm"]), float(p.get("vehicle_speed_kmh", 0.0)), None)  # type: ignore[arg-type]
        return run_uq(
            self.text, self._m.file, cycle=cycle, point=pt, inputs=inputs, correlations=correlations,
            samples=samples, seed=seed, sobol=sobol, percentiles=percentiles, limits=limits,
            series_points=series_points, confidence=confidence, bootstrap=bootstrap,
            calibration=calibration, out=out, threads=threads, client=client, batch_size=batch_size,
            threads_per_task=threads_per_task,
        )

    def __reduce__(self) -> Tuple[type, Tuple["_native.Model"]]:
        return (Model, (self._m,))

    def _repr_html_(self) -> str:
        c = self.check()
        rows: List[Tuple[str, object]] = [
            ("file", self.file),
            ("gears / meshes", f"{c['gears']} / {c['meshes']}"),
            ("gear states", ", ".join(str(g) for g in c["gear_states"] or [])),  # type: ignore[union-attr]
            ("thermal nodes", c["thermal_nodes"]),
            ("vehicle", c["vehicle"]),
            ("overrides", "; ".join(self.overrides) or "none"),
        ]
        return _html_table(f"Model {self.name!r}", rows)

    def __repr__(self) -> str:
        return repr(self._m)


def _point(
    gear: str, speed_rpm: float, torque_nm: float, vehicle_speed_kmh: float, ambient_c: Optional[float]
) -> Dict[str, object]:
    return {
        "gear": str(gear),
        "speed_rpm": float(speed_rpm),
        "torque_nm": float(torque_nm),
        "vehicle_speed_kmh": float(vehicle_speed_kmh),
        "ambient_c": None if ambient_c is None else float(ambient_c),
    }


def _scalars(d: Mapping[str, Json]) -> Dict[str, Json]:
    return {k: v for k, v in d.items() if not isinstance(v, (dict, list))}


def _steady_row(r: Mapping[str, Json]) -> Dict[str, Json]:
    row = _scalars(r)
    temps = r.get("temperatures_c")
    if isinstance(temps, dict):
        row.update({f"temp_{n}_c": t for n, t in temps.items()})
    return row


def _as_frame(
    report: Dict[str, Json], rows: Sequence[Mapping[str, Json]], output: str
) -> Union["pandas.DataFrame", Dict[str, Json]]:
    """The report as it is (``output="dict"``) or its rows as a DataFrame whose ``attrs`` hold
    the report."""
    if output == "dict":
        return report
    if output != "frame":
        raise ValueError(f"output={output!r}: 'frame' or 'dict'")
    import pandas as pd

    df = pd.DataFrame.from_records(list(rows))
    df.attrs.update(report)
    return df
