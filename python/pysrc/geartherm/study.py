"""Design studies from Python: the same runner as ``geartherm study`` (journal, resume,
compaction into ``study.csv``, ``study.parquet`` and the figures), on this machine's cores or on
a Dask cluster."""

from __future__ import annotations

import io
import json
import math
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

from . import _native
from ._tables import frame, html_table
from ._types import Json, JobSpec, ParameterSpec, PathLike
from .errors import InputError

if TYPE_CHECKING:
    import distributed
    import pandas
    import polars

    from . import Model

Progress = Union[bool, Callable[[int, int], None], None]
# A mapping {key path: its specification} or a list of specifications with a "path" (checked
# when the study is built: a wrong shape is a TypeError naming what is expected).
Parameters = Union[Mapping[str, object], Sequence[ParameterSpec]]
Backend = Literal["pandas", "polars"]

__all__ = ["Study", "study", "study_commands", "read_study"]


def _spec(parameters, job, sampling, name: str, outputs) -> Dict[str, Any]:
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
        "outputs": dict(outputs) if outputs is not None else {},
    }


class _Bar:
    """Progress: tqdm (``tqdm.auto``: a terminal bar, or a widget in Jupyter) when installed,
    else one line on standard error rewritten in place."""

    def __init__(self, total: int, name: str, progress: Progress):
        self.callback = progress if callable(progress) else None
        self.bar = None
        self.text = False
        self.last = -1
        if progress is True and total:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, desc=name, unit="case")
            except ImportError:
                self.text = True
        self.total = total
        self.name = name

    def __call__(self, done: int, total: int) -> None:
        if self.callback is not None:
            self.callback(done, total)
        if done == self.last:
            return
        if self.bar is not None:
            self.bar.update(done - max(self.last, 0))
        elif self.text:
            sys.stderr.write(f"\r{self.name}: {done}/{total} cases")
            sys.stderr.flush()
        self.last = done

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.text:
            sys.stderr.write("\n")


def _batch(spec_json: str, text: str, file: str, indices: List[int], threads: Optional[int]) -> str:
    """One Dask task: the study runner on a batch of cases of the shipped study and model text
    (nothing written; the rows as JSON)."""
    return _native.run_cases(spec_json, text, file, indices, threads)


class Study:
    """A design study: a base model, parameters varied by key path, a sampling plan and a job.

    Build one from values (the structure of a study file) or read a study file with
    :meth:`load`; :meth:`run` solves it.

    Parameters
    ----------
    model : Model or path
        The base model (without overrides: vary values through ``parameters``).
    parameters : mapping or sequence of mappings
        ``{key_path: {"range": [lo, hi]} | {"values": [...]} | {"scale": [lo, hi]}}``
        (``"levels": n`` for the grid points of a range), or a list of such mappings each with
        its ``"path"``.
    job : mapping, optional
        ``{"kind": "run", "cycles": ["wltc"], "options": {...}}`` (default: WLTC),
        ``{"kind": "steady", "points": [{"gear": "3", "speed_rpm": 2000, "torque_nm": 100}]}``
        or ``{"kind": "map", "gear": "3", "speed_rpm": [...], "torque_nm": [...]}``.
    sampling : mapping, optional
        ``{"plan": "grid"}`` (default), ``{"plan": "lhs", "cases": 1000, "seed": 7}`` or
        ``{"plan": "list"}``.
    name : str
        The study's name (progress bar, figures' titles).
    outputs : mapping, optional
        ``{"effects": [...], "pareto": [a, b], "per_case": bool}`` as in a study file.

    Raises
    ------
    InputError
        An invalid study (unknown key path, bad plan, an option out of range).
    ModelError
        An invalid base model.
    """

    def __init__(
        self,
        model: Union["Model", PathLike],
        parameters: Parameters,
        job: Optional[JobSpec] = None,
        sampling: Optional[JobSpec] = None,
        *,
        name: str = "study",
        outputs: Optional[JobSpec] = None,
    ):
        from . import Model

        if not isinstance(model, Model):
            model = Model.load(model)
        if model.overrides:
            raise InputError("Study: pass the base model without overrides; vary values through parameters")
        self._init(json.dumps(_spec(parameters, job, sampling, name, outputs)), model.text, model._m.file)

    def _init(self, spec_json: str, text: str, file: str) -> None:
        self._spec_json, self._text, self._file = spec_json, text, file
        self.spec: Dict[str, Any] = json.loads(spec_json)
        self.fingerprint, self.cases, self.outputs = _native.study_cases(spec_json, text, file)

    @classmethod
    def load(cls, path: PathLike) -> "Study":
        """Read a study file (the ``geartherm study`` TOML; its model path is relative to it).

        Raises :class:`FileNotFoundError` for a missing study or model file, :class:`InputError`
        for an invalid study."""
        spec_json, text, file = _native.study_file(os.fspath(path))
        s = cls.__new__(cls)
        s._init(spec_json, text, file)
        return s

    @property
    def name(self) -> str:
        return self.spec["study"]["name"]

    def model(self, case: int) -> "Model":
        """The model of case ``case`` (its position in :attr:`cases`): the base model with the
        case's parameter values as overrides (``.overrides`` lists them, :meth:`Model.to_toml`
        writes them in). Running it with :meth:`job`'s options gives the case's row."""
        from . import Model

        overrides, _ = _native.study_case(self._spec_json, self._text, self._file, case)
        return Model(_native.Model.from_text(self._text, self._file).with_overrides(overrides))

    def job(self, case: int) -> Dict[str, Json]:
        """The job of case ``case``: ``{"kind": "run", "options": {...}}`` (the options of
        :meth:`Model.run`: ``cycle``, ``solver``, ``rtol``, ``atol``, ``summary_only``, …) or
        ``{"kind": "steady", "options": {...}}`` (those of :meth:`Model.steady`)."""
        _, job = _native.study_case(self._spec_json, self._text, self._file, case)
        out: Dict[str, Json] = json.loads(job)
        return out

    def commands(self) -> List[str]:
        """The stand-alone ``geartherm run``/``steady`` command line of every case (for Slurm
        arrays or HyperQueue without Python)."""
        return _native.study_commands(self._spec_json, self._text, self._file)

    @overload
    def run(
        self,
        out: Optional[PathLike] = None,
        *,
        client: Optional["distributed.Client"] = None,
        progress: Progress = True,
        threads: Optional[int] = None,
        cases: Optional[Sequence[int]] = None,
        shard: Optional[Tuple[int, int]] = None,
        batch_size: Optional[int] = None,
        threads_per_task: Optional[int] = None,
        backend: Literal["pandas"] = ...,
    ) -> "pandas.DataFrame": ...
    @overload
    def run(
        self,
        out: Optional[PathLike] = None,
        *,
        client: Optional["distributed.Client"] = None,
        progress: Progress = True,
        threads: Optional[int] = None,
        cases: Optional[Sequence[int]] = None,
        shard: Optional[Tuple[int, int]] = None,
        batch_size: Optional[int] = None,
        threads_per_task: Optional[int] = None,
        backend: Literal["polars"],
    ) -> "polars.DataFrame": ...
    def run(
        self,
        out: Optional[PathLike] = None,
        *,
        client: Optional["distributed.Client"] = None,
        progress: Progress = True,
        threads: Optional[int] = None,
        cases: Optional[Sequence[int]] = None,
        shard: Optional[Tuple[int, int]] = None,
        batch_size: Optional[int] = None,
        threads_per_task: Optional[int] = None,
        backend: Backend = "pandas",
    ) -> Union["pandas.DataFrame", "polars.DataFrame"]:
        """Solve the study; one DataFrame row per case, in case order.

        Parameters
        ----------
        out : path, optional
            Output directory, as ``geartherm study --out``: every finished case is journaled
            there (``journal.jsonl``), a rerun resumes (journaled cases are not solved again),
            and at the end ``study.csv``, ``study.parquet``, ``main_effects.png`` and
            ``pareto.png`` are written, the same files the CLI writes. Without ``out`` nothing is
            written.
        client : distributed.Client, optional
            Run on a Dask cluster: the cases are cut into batches (``batch_size``, default about
            four per worker thread), each one task carrying the study and the model *text*.
        progress : bool or callable
            ``True`` (default): a progress bar (tqdm when installed: a terminal bar or a Jupyter
            widget). ``False``: none. A callable is called as ``progress(done, total)``.
        threads : int, optional
            Threads of a local run, 1 … 1024 (default: every core).
        cases : sequence of int, optional
            Only these positions in the case list, each once (the CLI's ``--cases``).
        shard : (i, n), optional
            Only shard ``i`` of ``n`` (cases i, i+n, …; ``0 ≤ i < n``), journaled as
            ``journal.shard-i-of-n``; a later run without ``shard`` merges the shards (the
            CLI's ``--shard I/N``). ``cases`` and ``shard`` are checked by the study layer, as
            for the CLI: an invalid one, or both at once, is an :class:`InputError` with the
            CLI's message.
        batch_size, threads_per_task : int, optional
            Dask batching and the threads one task uses (1 … 1024; also the threads of a local
            run when ``threads`` is not given).
        backend : {"pandas", "polars"}
            The DataFrame library of the result.

        Returns
        -------
        DataFrame
            Columns ``case``, ``sample``, ``job``, one per parameter (a scale parameter's column
            is ``PATH (scale)``), ``status`` (``ok``, ``invalid``, ``failed``), ``message``, then
            the outputs of docs/outputs.md (``energy_<source>_j``, ``energy_total_j``,
            ``temp_max_<node>_c``, … for runs; ``loss_<source>_w``, ``loss_total_w``,
            ``temp_<node>_c`` for steady points). A failing case is a row with its message; it
            does not stop the study.

        Ctrl-C (``KeyboardInterrupt``) stops the study cleanly: no new case starts, the running
        ones finish and are journaled, then the exception propagates; the same call resumes.
        """
        # The selection is built and checked by the study layer (the CLI's --cases/--shard).
        picked = None if cases is None else list(cases)
        args = (self._spec_json, self._text, self._file)
        total = len(_native.study_select(*args, picked, shard))
        if client is None and threads is None:
            threads = threads_per_task
        outdir = None if out is None else os.fspath(out)
        bar = _Bar(total, self.name, progress)
        try:
            if client is None:
                csv, self.tally = _native.run_study(*args, outdir, shard, picked, threads, bar, True)
            else:
                csv = self._run_dask(client, outdir, picked, shard, bar, batch_size, threads_per_task)
        finally:
            bar.close()
        return _study_frame(csv, self.spec, backend)

    def _run_dask(self, client, outdir, picked, shard, bar, batch_size, threads_per_task) -> str:
        """The runner's session here (selection, lock, resume, journal, compaction), its cases
        solved by Dask tasks that each run the runner on a batch (nothing written there)."""
        from distributed import as_completed

        args = (self._spec_json, self._text, self._file)
        session = _native.StudySession(*args, outdir, picked, shard)
        try:
            todo = session.todo()
            n = len(todo)
            if batch_size is None:
                workers = sum(client.nthreads().values()) or 1
                batch_size = max(1, math.ceil(n / (4 * workers)))
            batches = [todo[i : i + batch_size] for i in range(0, n, batch_size)]
            futures = [client.submit(_batch, *args, b, threads_per_task, pure=False) for b in batches]
            try:
                for f in as_completed(futures):
                    bar(session.record(f.result()), n)
            except BaseException:
                client.cancel(futures)
                raise
            csv, self.tally = session.finish()
        finally:
            session.close()
        return csv

    def _repr_html_(self) -> str:
        s = self.spec
        rows = [
            ("job", json.dumps(s["job"])),
            ("sampling", json.dumps(s["sampling"])),
            ("parameters", ", ".join(p["path"] for p in s["parameters"])),
            ("cases", len(self.cases)),
            ("outputs", ", ".join(self.outputs)),
        ]
        return html_table(f"Study {self.name!r}", rows)

    def __repr__(self) -> str:
        return f"Study({self.name!r}: {len(self.cases)} cases, {len(self.spec['parameters'])} parameters)"


def _text_columns(spec: Mapping[str, Any]) -> List[str]:
    cols = []
    for p in spec["parameters"]:
        vals = p.get("values")
        if vals and any(isinstance(v, str) for v in vals):
            cols.append(p["path"])
    return cols


def _study_frame(csv: str, spec: Mapping[str, Any], backend: str = "pandas"):
    return frame(csv, _text_columns(spec), backend)


@overload
def study(
    model: Union["Study", "Model", PathLike],
    parameters: Optional[Parameters] = None,
    job: Optional[JobSpec] = None,
    sampling: Optional[JobSpec] = None,
    *,
    out: Optional[PathLike] = None,
    client: Optional["distributed.Client"] = None,
    progress: Progress = True,
    threads: Optional[int] = None,
    batch_size: Optional[int] = None,
    threads_per_task: Optional[int] = None,
    cases: Optional[Sequence[int]] = None,
    shard: Optional[Tuple[int, int]] = None,
    name: str = "study",
    outputs: Optional[JobSpec] = None,
    backend: Literal["pandas"] = ...,
) -> "pandas.DataFrame": ...
@overload
def study(
    model: Union["Study", "Model", PathLike],
    parameters: Optional[Parameters] = None,
    job: Optional[JobSpec] = None,
    sampling: Optional[JobSpec] = None,
    *,
    out: Optional[PathLike] = None,
    client: Optional["distributed.Client"] = None,
    progress: Progress = True,
    threads: Optional[int] = None,
    batch_size: Optional[int] = None,
    threads_per_task: Optional[int] = None,
    cases: Optional[Sequence[int]] = None,
    shard: Optional[Tuple[int, int]] = None,
    name: str = "study",
    outputs: Optional[JobSpec] = None,
    backend: Literal["polars"],
) -> "polars.DataFrame": ...
def study(
    model: Union["Study", "Model", PathLike],
    parameters: Optional[Parameters] = None,
    job: Optional[JobSpec] = None,
    sampling: Optional[JobSpec] = None,
    *,
    out: Optional[PathLike] = None,
    client: Optional["distributed.Client"] = None,
    progress: Progress = True,
    threads: Optional[int] = None,
    batch_size: Optional[int] = None,
    threads_per_task: Optional[int] = None,
    cases: Optional[Sequence[int]] = None,
    shard: Optional[Tuple[int, int]] = None,
    name: str = "study",
    outputs: Optional[JobSpec] = None,
    backend: Backend = "pandas",
) -> Union["pandas.DataFrame", "polars.DataFrame"]:
    """Run a design study and return one DataFrame row per case.

    ``study("models/studies/at6_wltc_lhs.toml", out="studies/at6")`` runs a study file (a
    :class:`Study` is accepted too); ``study(model, parameters, job, sampling)`` builds the study
    from values (see :class:`Study` for their structure). Every other argument is
    :meth:`Study.run`'s: ``out`` (journal, resume, the CLI's files), ``client`` (Dask),
    ``progress``, ``threads``, ``cases``, ``shard``, ``batch_size``, ``threads_per_task``,
    ``backend``.
    """
    if isinstance(model, Study):
        s = model
    elif parameters is None:
        s = Study.load(model)  # type: ignore[arg-type]
    else:
        s = Study(model, parameters, job, sampling, name=name, outputs=outputs)
    return s.run(  # type: ignore[call-overload,no-any-return]
        out,
        client=client,
        progress=progress,
        threads=threads,
        cases=cases,
        shard=shard,
        batch_size=batch_size,
        threads_per_task=threads_per_task,
        backend=backend,
    )


def study_commands(
    model: Union["Study", "Model", PathLike],
    parameters: Optional[Parameters] = None,
    job: Optional[JobSpec] = None,
    sampling: Optional[JobSpec] = None,
) -> List[str]:
    """The stand-alone ``geartherm run``/``steady`` command line of every case (for Slurm arrays
    or HyperQueue without Python); arguments as :func:`study`."""
    s = model if isinstance(model, Study) else Study.load(model) if parameters is None else Study(model, parameters, job, sampling)
    return s.commands()


@overload
def read_study(directory: PathLike, backend: Literal["pandas"] = ...) -> "pandas.DataFrame": ...
@overload
def read_study(directory: PathLike, backend: Literal["polars"]) -> "polars.DataFrame": ...
def read_study(directory: PathLike, backend: Backend = "pandas") -> Union["pandas.DataFrame", "polars.DataFrame"]:
    """The table of a study directory (``study.csv`` written by ``geartherm study`` or
    :func:`study` with ``out=``) as the DataFrame :func:`study` returned for it."""
    d = Path(directory)
    csv = (d / "study.csv").read_text()
    # Text parameters: the columns between `job` and `status` whose values are not numbers.
    import pandas as pd

    raw = pd.read_csv(io.StringIO(csv), dtype=str, keep_default_na=False)
    header = list(raw.columns)
    params = header[3 : header.index("status")] if "status" in header else []
    text = [c for c in params if not _numeric(raw[c])]
    out: Union["pandas.DataFrame", "polars.DataFrame"] = frame(csv, text, backend)
    return out


def _numeric(col) -> bool:
    for v in col:
        if v == "":
            continue
        try:
            float(v)
        except ValueError:
            return False
    return True
