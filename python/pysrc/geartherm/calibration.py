"""Calibration results and measured traces from Python: the files ``geartherm calibrate``
writes, figures, and trace files read as ``geartherm trace`` reads them."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Dict, List, Literal, Optional, Sequence, Tuple, TypedDict, Union

from . import _native
from ._tables import frame, html_table
from ._types import Json, PathLike

if TYPE_CHECKING:
    import matplotlib.figure
    import pandas

    from . import Model

__all__ = ["CalibrationResult", "TraceFile", "read_trace", "calibrate_traces"]


class CalibrationResult:
    """A calibration (``Model.calibrate``).

    Attributes
    ----------
    summary : dict
        ``calibration.json``.
    parameters : pandas.DataFrame
        One row per fitted parameter: ``key_path``, ``start``, ``value``, ``lower_bound``,
        ``upper_bound``, ``scale``, ``std_error``, ``ci95_low``, ``ci95_high``,
        ``influence_k``, ``identifiable``, … (the ``parameters`` of ``calibration.json``).
    correlation : pandas.DataFrame
        Parameters × parameters.
    errors : pandas.DataFrame
        Per measured channel and part (``rows_of``: ``fitted``, ``holdout``): ``rows``,
        ``rmse_k``, ``max_abs_k``, ``bias_k``, ``inside_band95``, and the band's multiplier of
        its standard deviation (``band_multiplier``; ``band_quantile``: ``empirical`` or ``t``).
    fit : pandas.DataFrame
        ``fit.csv``: ``time_s``, ``held_out``, and per channel ``<node>_measured_c``,
        ``<node>_simulated_c``, ``<node>_residual_k``, ``<node>_band95_k`` (the 95 % prediction
        band's half-width) and the band itself, ``<node>_band95_low_c`` and
        ``<node>_band95_high_c``.
    priors : pandas.DataFrame
        One row per prior: ``key_path``, ``distribution``, ``location``, ``width``,
        ``prior_sd``, ``data_std_error``, ``posterior_std_error``, ``width_ratio``,
        ``prior_share``, ``without_prior`` (empty without priors).
    profiles : pandas.DataFrame
        The profile likelihoods asked for: ``key_path``, ``value``, ``statistic``,
        ``threshold``; :attr:`summary` ``["profiles"]`` has their intervals.
    plausibility : pandas.DataFrame
        The calibrated model's loss per source (``at``: ``highest_power`` or ``rated``;
        ``source``, ``loss_w``, ``power_w``, ``efficiency``, ``oil_temp_c``); empty when not
        evaluated.
    traces : pandas.DataFrame
        A fit over several traces: per trace, channel and part (``rows_of``) its errors
        (``rmse_k``, ``inside_band95``, …); empty for one segment.
    warnings : list of str
    calibrated_text : str
        The model text with the fitted values written in (``calibrated.toml``);
        :attr:`calibrated` is it as a :class:`Model`.
    """

    def __init__(
        self,
        summary_json: str,
        fit_csv: str,
        calibrated_text: str,
        cycle_csv: str,
        files: Sequence[Tuple[str, bytes]] = (),
    ):
        import pandas as pd

        self._args = (summary_json, fit_csv, calibrated_text, cycle_csv, list(files))
        self.summary: Dict[str, Json] = json.loads(summary_json)
        s = json.loads(summary_json)
        self.parameters: "pandas.DataFrame" = pd.DataFrame(s["parameters"])
        c = s["correlation"]
        self.correlation: "pandas.DataFrame" = pd.DataFrame(
            [[math.nan if x is None else x for x in row] for row in c["matrix"]],
            index=c["parameters"],
            columns=c["parameters"],
        )
        rows = []
        for ch in s["channels"]:
            for part in ("fitted", "holdout"):
                e = ch[part]
                if e is not None:
                    rows.append({"node": ch["node"], "rows_of": part, **e,
                                 "band_multiplier": ch["noise"]["band_multiplier"],
                                 "band_quantile": ch["noise"]["band_quantile"]})
        self.errors: "pandas.DataFrame" = pd.DataFrame(rows)
        self.fit: "pandas.DataFrame" = frame(fit_csv, text=("trace",))
        for ch in s["channels"]:
            n = ch["node"]
            if f"{n}_band95_k" in self.fit.columns:
                self.fit[f"{n}_band95_low_c"] = self.fit[f"{n}_simulated_c"] - self.fit[f"{n}_band95_k"]
                self.fit[f"{n}_band95_high_c"] = self.fit[f"{n}_simulated_c"] + self.fit[f"{n}_band95_k"]
        self.priors: "pandas.DataFrame" = pd.DataFrame(
            [{"key_path": p["key_path"], **p["prior"]} for p in s["parameters"] if p.get("prior")]
        )
        self.profiles: "pandas.DataFrame" = pd.DataFrame(
            [
                {"key_path": p["key_path"], "threshold": p["threshold"], **x}
                for p in s.get("profiles", [])
                for x in p["points"]
            ]
        )
        plaus = []
        pl = s.get("plausibility") or {}
        for at in ("highest_power", "rated"):
            x = pl.get(at)
            if x:
                for src, w in x["loss_by_source_w"]:
                    plaus.append(
                        {
                            "at": at,
                            "source": src,
                            "loss_w": w,
                            "power_w": x["power_w"],
                            "efficiency": x["efficiency"],
                            "oil_temp_c": x["oil_temp_c"],
                        }
                    )
        self.plausibility: "pandas.DataFrame" = pd.DataFrame(plaus)
        self.warnings: List[str] = list(s["warnings"])
        self.traces: "pandas.DataFrame" = pd.DataFrame(
            [
                {"trace": t["name"], "index": t["index"], "segments": len(t["segments"]), "node": ch["node"],
                 "rows_of": part, **ch[part]}
                for t in s.get("traces", [])
                for ch in t["channels"]
                for part in ("fitted", "holdout")
                if ch[part] is not None
            ]
        )
        self.calibrated_text = calibrated_text
        self.cycle_csv = cycle_csv
        self._sigma = float(s["fit"]["sigma_k"])

    @property
    def calibrated(self) -> "Model":
        """The model with the fitted values written in."""
        from . import Model

        return Model.from_text(self.calibrated_text, "calibrated.toml")

    def write(self, directory: PathLike) -> Path:
        """Write the files ``geartherm calibrate --out DIR`` writes, byte for byte:
        ``calibration.json``, ``fit.csv``, ``calibrated.toml``, ``cycle.csv`` and
        ``calibration.png`` (drawn by the same code as the CLI's)."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        for name, data in self._args[4]:
            (d / name).write_bytes(bytes(data))
        _native.render_calibration(os.fspath(d))
        return d

    def plot(self) -> "matplotlib.figure.Figure":
        """Measured and simulated temperature of every channel over time (held-out rows
        shaded), and the residuals below (matplotlib; ``pip install "geartherm[plot]"``)."""
        from .plots import calibration_figure

        return calibration_figure(self.fit)

    def __reduce__(self) -> Tuple[type, Tuple[object, ...]]:
        return (CalibrationResult, self._args)

    def _repr_html_(self) -> str:
        rows: List[Tuple[str, object]] = []
        for _, p in self.parameters.iterrows():
            lo, hi = p.get("ci95_low"), p.get("ci95_high")
            ci = "" if lo is None or hi is None or lo != lo else f" (95 %: {lo:.4g} … {hi:.4g})"
            rows.append((str(p["key_path"]), f"{p['value']:.6g}{ci}"))
        rows.append(("σ", f"{self._sigma:.3g} K"))
        for _, e in self.errors.iterrows():
            rows.append((f"{e['node']} RMSE ({e['rows_of']})", f"{e['rmse_k']:.3g} K"))
        rows.append(("warnings", len(self.warnings)))
        return html_table("Calibration", rows)

    def __repr__(self) -> str:
        return f"CalibrationResult({len(self.parameters)} parameter(s), σ = {self._sigma:.3g} K)"


class SegmentSummary(TypedDict):
    """One segment of a trace file: its first and last line, rows, the time of its first row
    in the file and its duration, s."""

    first_line: int
    last_line: int
    rows: int
    start_s: float
    duration_s: float


class TraceSummary(TypedDict):
    """``geartherm trace --json``: rows read, kept and dropped, empty cells per column, the
    segments, the node and boundary columns."""

    source: str
    rows: int
    kept_rows: int
    dropped_rows: int
    missing_cells: Dict[str, int]
    segments: List[SegmentSummary]
    nodes: List[str]
    boundaries: List[str]


class TraceFile:
    """A measured trace file read as ``geartherm trace`` and ``geartherm calibrate`` read it.

    Attributes
    ----------
    summary : dict
        ``geartherm trace --json``: ``rows``, ``kept_rows``, ``dropped_rows``,
        ``missing_cells`` (empty cells per column), ``segments`` (per segment: ``first_line``,
        ``last_line``, ``rows``, ``start_s``, ``duration_s``), ``nodes``, ``boundaries``.
    segments : list of pandas.DataFrame
        Each segment's rows with the file's columns; in a file of several segments each one's
        ``time_s`` counts from its own first row (``offsets_s`` holds that row's time).
    offsets_s : list of float
    dropped_rows : int
        Rows dropped for an empty cell.
    missing_cells : dict
        Empty cells per column.
    """

    def __init__(self, summary_json: str, segments: Sequence[Tuple[float, str]]):
        self.summary: TraceSummary = json.loads(summary_json)
        s = self.summary
        self.offsets_s: List[float] = [float(o) for o, _ in segments]
        self.segments: List["pandas.DataFrame"] = [frame(csv) for _, csv in segments]
        self.dropped_rows: int = int(s["dropped_rows"])
        self.missing_cells: Dict[str, int] = {str(k): int(v) for k, v in s["missing_cells"].items()}

    def __repr__(self) -> str:
        rows = sum(len(s) for s in self.segments)
        return f"TraceFile({len(self.segments)} segment(s), {rows} rows, {self.dropped_rows} dropped)"


def read_trace(
    trace: Union[PathLike, "pandas.DataFrame"],
    *,
    missing: Literal["drop", "refuse"] = "drop",
    name: Optional[str] = None,
) -> TraceFile:
    """Read a measured trace (a CSV file or a DataFrame) as ``geartherm calibrate`` reads it:
    rows with an empty cell dropped and counted (``missing="refuse"``: an error naming line and
    column), the record cut into segments at its gaps in time (a step over ten times the median
    step).

    Raises
    ------
    InputError
        A bad cell, an unknown column (file, line, column and value named).
    FileNotFoundError
        No such file.
    """
    text, label = _trace_text(trace, name)
    if missing not in ("drop", "refuse"):
        raise ValueError(f"missing={missing!r}: 'drop' or 'refuse'")
    summary, segments = _native.read_trace(text, label, missing == "refuse")
    return TraceFile(summary, segments)


def _trace_text(trace: Union[PathLike, "pandas.DataFrame"], name: Optional[str]) -> Tuple[str, str]:
    if isinstance(trace, (str, os.PathLike)):
        label = os.fspath(trace)
        with open(label, encoding="utf-8") as fh:
            return fh.read(), name or label
    return trace.to_csv(index=False), name or "trace"


def _segments_of(native, traces, options, theta, which):
    """A Dask worker's share: the residuals and Jacobians of the segments ``which`` at θ."""
    return native.evaluate_segments(traces, options, list(theta), list(which))


def calibrate_traces(native, traces, options, client=None) -> CalibrationResult:
    """Calibrate over several traces ((CSV text, name, label) triples: the label names the file
    in messages, its path as ``geartherm calibrate`` names it, or the name for a DataFrame).
    With a Dask ``client`` every evaluation of the fit spreads the segments over the workers
    (each integrates its segments' residuals and sensitivities through ``evaluate_segments``);
    the Levenberg–Marquardt steps, the statistics and the report are computed here, by the same
    code as the local fit."""
    if client is None:
        return CalibrationResult(*native.calibrate_traces(traces, options))
    n = native.segment_count(traces, options)
    workers = max(1, len(client.scheduler_info().get("workers", {})))
    chunks = [list(range(k, n, workers)) for k in range(min(workers, n))]
    shared = client.scatter([native, traces, options], broadcast=True)

    def evaluator(theta):
        futures = [client.submit(_segments_of, *shared, list(theta), c, pure=False) for c in chunks]
        parts = [None] * n
        for c, out in zip(chunks, client.gather(futures)):
            for k, e in zip(c, out):
                parts[k] = e
        return parts

    return CalibrationResult(*native.calibrate_traces(traces, options, evaluator))
