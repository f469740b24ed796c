"""Uncertainty studies from Python: :meth:`geartherm.Model.uq`.

The options go to the library's use case as one JSON document (every check there, as for
``geartherm uq``); the cases run on the study runner (journal and resume with ``out``). The
result holds the summary (``uq.json``) and DataFrames: the bands with one column per series and
percentile (``temp_p05_sump_c``), the exceedance table, the Sobol table and the sample table.
"""

import io
import json
import math
import os
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Union

import pandas as pd

from . import _native

if TYPE_CHECKING:
    import distributed


class UqResult:
    """The outcome of :meth:`geartherm.Model.uq`.

    Attributes
    ----------
    summary : dict
        ``uq.json`` (inputs, percentiles, exceedance, sobol, energy, scalars, failed_samples, notes).
    bands : pandas.DataFrame
        ``time_s`` index; ``temp_pPP_<node>_c`` and ``energy_pPP_<source>_j`` columns (empty for a
        steady point).
    exceedance : pandas.DataFrame
        One row per limit: node, limit_c, count, n, probability, lo, hi, confidence.
    sobol : pandas.DataFrame
        One row per output and input: first, first_lo, first_hi, total, total_lo, total_hi.
    samples : pandas.DataFrame
        One row per sample: the sampled values, status and the scalar outputs.
    """

    def __init__(self, summary: str, bands: str, samples: str):
        self.summary: Dict[str, Any] = json.loads(summary)
        self.bands = pd.read_csv(io.StringIO(bands)).set_index("time_s") if bands else pd.DataFrame()
        self.exceedance = pd.DataFrame.from_records(self.summary["exceedance"])
        self.sobol = pd.DataFrame.from_records(self.summary["sobol"])
        self.samples = pd.read_csv(io.StringIO(samples))

    def __repr__(self) -> str:
        s = self.summary
        return f"UqResult({s['model']!r}, {s['cycle_or_point']!r}, {s['samples']} samples, {s['failed_samples']} failed)"


def _input(i: Mapping[str, Any]) -> Dict[str, Any]:
    return {k: v for k, v in i.items() if v is not None}


def run_uq(
    text: str,
    file: str,
    *,
    cycle: Optional[str] = None,
    point: Optional[Dict[str, object]] = None,
    inputs: Optional[Sequence[Mapping[str, Any]]] = None,
    correlations: Optional[Sequence[Mapping[str, Any]]] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    sobol: bool = False,
    percentiles: Sequence[float] = (5.0, 50.0, 95.0),
    limits: Optional[Mapping[str, float]] = None,
    series_points: int = 201,
    confidence: float = 0.95,
    bootstrap: int = 200,
    calibration: Optional[Mapping[str, Any]] = None,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: Optional[int] = None,
    client: Optional["distributed.Client"] = None,
    batch_size: Optional[int] = None,
    threads_per_task: Optional[int] = 1,
) -> UqResult:
    job: Optional[Dict[str, Any]] = None
    if point is not None:
        job = {"kind": "steady", **point}
    elif cycle is not None:
        job = {"kind": "run", "cycle": str(cycle), "summary_only": True}
    o: Dict[str, Any] = {
        "job": job,
        "samples": samples,
        "seed": seed,
        "sobol": bool(sobol),
        "percentiles": [float(p) for p in percentiles],
        "limits": [{"node": str(k), "temp_c": float(v)} for k, v in (limits or {}).items()],
        "series_points": int(series_points),
        "confidence": float(confidence),
        "bootstrap": int(bootstrap),
        "inputs": None,
        "calibration": None if calibration is None else dict(calibration),
    }
    if inputs is not None:
        o["inputs"] = {"inputs": [_input(i) for i in inputs], "correlations": [dict(c) for c in correlations or []]}
    target = None if out is None else os.fspath(out)
    if client is not None:
        return UqResult(*_run_dask(client, text, file, json.dumps(o), target, batch_size, threads_per_task))
    return UqResult(*_native.run_uq(text, file, json.dumps(o), target, threads))


def _batch(text: str, file: str, options: str, indices: List[int], threads: Optional[int]) -> str:
    """One Dask task: the samples at ``indices`` solved by the runner (nothing written; rows as
    JSON)."""
    return _native.uq_cases(text, file, options, indices, threads)


def _run_dask(client, text, file, options, out, batch_size, threads_per_task):
    """The runner's session here (journal, resume, lock), the samples solved by Dask tasks, the
    estimates made here from every row (as the local path makes them)."""
    from distributed import as_completed

    session = _native.UqSession(text, file, options, out)
    try:
        todo = session.todo()
        n = len(todo)
        if batch_size is None:
            workers = sum(client.nthreads().values()) or 1
            batch_size = max(1, math.ceil(n / (4 * workers)))
        batches = [todo[i : i + batch_size] for i in range(0, n, batch_size)]
        futures = [client.submit(_batch, text, file, options, b, threads_per_task, pure=False) for b in batches]
        try:
            for f in as_completed(futures):
                session.record(f.result())
        except BaseException:
            client.cancel(futures)
            raise
        return session.finish()
    finally:
        session.close()


__all__: List[str] = ["UqResult", "run_uq"]
