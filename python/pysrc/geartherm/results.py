"""Results of a drive-cycle run, and reading a run directory back."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Dict, List, Literal, Optional, Tuple, TypedDict, Union

from ._tables import frame, html_table
from ._types import PathLike

if TYPE_CHECKING:
    import matplotlib.figure
    import pandas
    import polars

__all__ = ["RunResult", "RunSummary", "read_run"]


class RangeWarningEntry(TypedDict):
    """One range warning: the loss ``item``, the ``range`` its model holds in, what was ``seen``."""

    item: str
    range: str
    seen: str


class TemperatureStats(TypedDict):
    """Temperatures of one node over a run, °C."""

    min: float
    max: float
    final: float


class RunSummary(TypedDict, total=False):
    """The ``summary.json`` of a run: energies per source, efficiencies, temperatures per node,
    warnings, the solver's figures (docs/outputs.md lists every key)."""

    model: str
    cycle: str
    solver: str
    rtol: float
    atol: float
    wall_time_s: float
    steps: int
    duration_s: float
    energy_lost_j: Dict[str, float]
    energy_by_item_j: List[Dict[str, Union[str, float]]]
    energy_stored_j: float
    energy_to_boundaries_j: float
    energy_balance_relative: float
    output_energy_j: float
    cycle_efficiency: Optional[float]
    energy_efficiency: Optional[float]
    temperatures_c: Dict[str, TemperatureStats]
    oil_node: str
    skipped: List[Dict[str, str]]
    frozen_viscosity: bool
    warnings: List[RangeWarningEntry]


class RunResult:
    """A drive-cycle run.

    Attributes
    ----------
    summary : dict
        The ``summary.json`` contents (docs/outputs.md): ``energy_lost_j`` (J per source and
        ``total``), ``energy_by_item_j``, ``output_energy_j``, ``cycle_efficiency``,
        ``energy_efficiency``, ``temperatures_c`` (min/max/final per node, °C), ``warnings``,
        the solver block.
    timeseries : pandas.DataFrame or None
        The ``timeseries.csv`` columns (units in the names: ``time_s``, ``temp_<node>_c``,
        ``loss_<source>_w``, ``loss_<source>_<item>_w``, ``loss_total_w``, ``efficiency``);
        None for a run with ``summary_only=True``.
    """

    def __init__(self, summary_json: str, timeseries_csv: Optional[str]):
        self._summary_json = summary_json
        self._csv = timeseries_csv
        self.summary: RunSummary = json.loads(summary_json)
        self._frame: Optional["pandas.DataFrame"] = None

    @property
    def timeseries(self) -> Optional["pandas.DataFrame"]:
        if self._csv is None:
            return None
        if self._frame is None:
            self._frame = frame(self._csv)
        return self._frame

    def to_polars(self) -> Optional["polars.DataFrame"]:
        """The time series as a polars DataFrame (needs ``polars``); None without one."""
        return None if self._csv is None else frame(self._csv, backend="polars")

    def write(self, directory: PathLike, *, parquet: bool = False) -> Path:
        """Write ``summary.json`` and ``timeseries.csv`` (when present) into ``directory``, the
        files ``geartherm run --out`` writes; with ``parquet=True`` also ``timeseries.parquet``
        (the same columns and dtypes as the CSV read back). :func:`read_run` reads them back."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        (d / "summary.json").write_text(json.dumps(self.summary, indent=2) + "\n")
        if self._csv is not None:
            (d / "timeseries.csv").write_text(self._csv)
            if parquet:
                self.to_parquet(d / "timeseries.parquet")
        return d

    def to_parquet(self, path: PathLike) -> None:
        """Write the time series as Parquet (pyarrow): the columns and dtypes of
        :attr:`timeseries`, which ``pandas.read_parquet`` gives back equal."""
        ts = self.timeseries
        if ts is None:
            raise ValueError("a summary-only run has no time series")
        ts.to_parquet(path, index=False)

    def plot(self, kind: Literal["all", "temperatures", "losses", "energy"] = "all") -> "matplotlib.figure.Figure":
        """Draw the run report's figures with matplotlib (``pip install "geartherm[plot]"``).

        Parameters
        ----------
        kind : {"all", "temperatures", "losses", "energy"}
            Temperatures of every capacity node over time (°C), loss per source over time
            (stacked, W), energy per source (kJ); ``"all"`` draws the three on one figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from .plots import run_figure

        return run_figure(self, kind)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, RunResult):
            return NotImplemented
        a, b = dict(self.summary), dict(other.summary)
        # The integration's wall time is the one figure two equal runs do not share.
        a.pop("wall_time_s", None)
        b.pop("wall_time_s", None)
        return a == b and self._csv == other._csv

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> "Tuple[type, Tuple[str, Optional[str]]]":
        return (RunResult, (self._summary_json, self._csv))

    def _repr_html_(self) -> str:
        s = self.summary
        e = s.get("energy_lost_j", {})
        rows: List[Tuple[str, object]] = [("cycle", s.get("cycle")), ("duration", f"{s.get('duration_s', 0):.0f} s")]
        rows += [(k, f"{v / 1e3:.2f} kJ") for k, v in e.items() if v]
        for k in ("cycle_efficiency", "energy_efficiency"):
            v = s.get(k)
            if isinstance(v, float):
                rows.append((k, f"{v:.4f}"))
        rows += [(f"{n} (max / final)", f"{t['max']:.1f} / {t['final']:.1f} °C") for n, t in s.get("temperatures_c", {}).items()]
        rows.append(("warnings", len(s.get("warnings", []))))
        return html_table(f"Run of {s.get('model')!r}", rows)

    def __repr__(self) -> str:
        s = self.summary
        return f"RunResult({s.get('model')!r} over {s.get('cycle')!r}: {s['energy_lost_j']['total'] / 1e3:.1f} kJ lost)"


def read_run(directory: PathLike) -> RunResult:
    """A run directory (``geartherm run --out DIR`` or :meth:`RunResult.write`) as the
    :class:`RunResult` the run returned, read with the writer's types (the library's ``Summary``
    and time-series table, as ``geartherm report`` reads it): a directory of an earlier version
    reads with today's keys (``mean_efficiency`` as ``cycle_efficiency``, keys it lacks at their
    defaults).

    Raises :class:`FileNotFoundError` when ``summary.json`` is missing."""
    from . import _native

    summary, csv = _native.read_run(str(Path(directory)))
    return RunResult(summary, csv)
