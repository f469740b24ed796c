"""Exceptions and warnings of geartherm.

Every exception is a plain Python class importable from :mod:`geartherm`, and pickles with its
fields, so a failure in a ``multiprocessing`` worker, a Dask task or a Ray task arrives whole:

>>> import pickle, geartherm
>>> e = geartherm.ModelError("bad", path="gears[0].teeth", value="-3", allowed="> 0")
>>> pickle.loads(pickle.dumps(e)).path
'gears[0].teeth'

============================  =================================  ==========================
class                         raised for                         also a
============================  =================================  ==========================
:class:`ModelError`           an invalid model file or override  :class:`ValueError`
:class:`InputError`           an invalid argument or study       :class:`ValueError`
:class:`SolveError`           a numerical failure                :class:`RuntimeError`
:class:`FileNotFoundError`    a missing model, cycle or study    (Python's own)
:class:`OSError`              another I/O failure                (Python's own)
============================  =================================  ==========================
"""

from __future__ import annotations

import errno as _errno
import json as _json
import re as _re
from typing import Dict, List, Optional, Sequence, Tuple, Union

__all__ = [
    "GearthermError",
    "ModelError",
    "InputError",
    "SolveError",
    "RangeWarning",
]

Problem = Tuple[str, str, str]

#: A value as a model file or an option holds it.
Value = Union[None, bool, int, float, str, List["Value"], Dict[str, "Value"]]


class GearthermError(Exception):
    """Base class of geartherm's errors.

    Attributes
    ----------
    message : str
        The message, as the CLI prints it (file, key path, value, allowed range).
    file : str or None
        The model, trace or cycle file (or the name given to text).
    line : int or None
        The line in that file, for a trace or a cycle.
    path : str or None
        Key path of the first problem (``"lubrication.oil_level_mm"``), the option's name or
        the trace's column.
    value : bool, int, float, str, list, dict or None
        The value given there, as its Python type (``1.4``, not ``"1.4"``; ``""`` for an empty
        cell).
    allowed : str or None
        What is allowed there (a range with its unit, a list of names).
    problems : list of (path, value, allowed)
        Every problem found, the values as written (a model check reports every independent
        problem at once; the problems a first one causes are left out).
    """

    def __init__(
        self,
        message: str,
        *,
        path: Optional[str] = None,
        value: Value = None,
        allowed: Optional[str] = None,
        problems: Sequence[Problem] = (),
        file: Optional[str] = None,
        line: Optional[int] = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.problems: List[Problem] = [(str(p[0]), str(p[1]), str(p[2])) for p in problems]
        first = self.problems[0] if self.problems else None
        self.path = path if path is not None or first is None else first[0]
        self.value: Value = value if value is not None or first is None else typed(first[1])
        self.allowed = allowed if allowed is not None or first is None else first[2]
        self.file = file
        self.line = line

    def __reduce__(self) -> Tuple[object, ...]:
        fields = {
            "path": self.path,
            "value": self.value,
            "allowed": self.allowed,
            "problems": self.problems,
            "file": self.file,
            "line": self.line,
        }
        return (_rebuild, (type(self), self.message, fields))

    def __str__(self) -> str:
        return self.message

    def __repr__(self) -> str:
        fields = ", ".join(f"{k}={getattr(self, k)!r}" for k in ("file", "line", "path", "value", "allowed") if getattr(self, k) is not None)
        return f"{type(self).__name__}({self.message!r}{', ' if fields else ''}{fields})"


def _rebuild(cls: type, message: str, fields: Dict[str, object]) -> GearthermError:
    err: GearthermError = cls(message, **fields)
    return err


def typed(text: str) -> Value:
    """A value written as TOML (or a cell's text) as its Python value: ``"1.4"`` → 1.4,
    ``'"fva_3a"'`` → ``"fva_3a"``, ``"true"`` → True, ``"[1, 2]"`` → [1, 2]; text that is no
    value stays text."""
    t = text.strip()
    if not t:
        return t
    try:
        v: Value = _json.loads(t)
        return v
    except ValueError:
        pass
    if t.lower().lstrip("+-") in ("inf", "nan"):
        return float(t)
    if len(t) >= 2 and t[0] == t[-1] == "'":
        return t[1:-1]
    try:
        return float(t.replace("_", "")) if any(c.isdigit() for c in t) else t
    except ValueError:
        return t


# `FILE, line N: column C = "V": what` (a trace or cycle cell), `FILE, line N: what`.
_AT_LINE = _re.compile(r'^(?:cycle: )?(?P<file>.+?), line (?P<line>\d+): (?:column (?P<col>[^=]+?) = "(?P<val>[^"]*)": )?(?P<what>.*)$', _re.S)


class ModelError(GearthermError, ValueError):
    """An invalid model file or override.

    ``.problems`` lists every problem, ``.path`` is the first key path."""


class InputError(GearthermError, ValueError):
    """An invalid argument: unknown cycle or gear, an option out of its range, an invalid study.

    ``.path`` names the option, ``.value`` the value given, ``.allowed`` its range."""


class SolveError(GearthermError, RuntimeError):
    """A numerical failure: a run that cannot integrate, a point without equilibrium.

    The message names the time, the node or the loss item (as the CLI's exit 2)."""


class RangeWarning(UserWarning):
    """A loss model used outside the range it was fitted on, or a loss item not counted.

    Raised for each entry of the ``warnings`` of a run's summary, a steady point or a losses
    report; filter them with :func:`warnings.simplefilter` as any warning."""


def _from_native(
    kind: str,
    message: str,
    problems: Sequence[Problem],
    file: Optional[str],
    fields: Optional[Dict[str, object]] = None,
) -> BaseException:
    """The exception for a failure reported by the native module (called from Rust): ``fields``
    (``path``, ``value`` as TOML text, ``allowed``, ``line``) where the library knows them, else
    the first problem's and what the message's ``FILE, line N: column C = "V": …`` says."""
    if kind == "not_found":
        return FileNotFoundError(_errno.ENOENT, message, file) if file else FileNotFoundError(_errno.ENOENT, message)
    if kind == "io":
        return OSError(_errno.EIO, message, file) if file else OSError(message)
    cls = {"model": ModelError, "input": InputError, "solve": SolveError}.get(kind, GearthermError)
    f = dict(fields or {})
    kw: Dict[str, object] = {"file": file}
    m = _AT_LINE.match(message)
    if m:
        kw.update(file=m["file"], line=int(m["line"]))
        if m["col"] is not None:
            kw.update(path=m["col"].strip(), value=typed(m["val"]), allowed=m["what"].strip())
    for k in ("path", "allowed", "line"):
        if f.get(k) is not None:
            kw[k] = f[k]
    if f.get("value") is not None:
        kw["value"] = typed(str(f["value"]))
    if cls is InputError and not m and problems:
        kw["value"] = _option_value(str(kw.get("path") or problems[0][0]), problems[0][1])
    err: BaseException = cls(message, problems=problems, **kw)  # type: ignore[arg-type]
    return err


# Options whose values are names (kept as text) and those that are counts (int); every other
# option is a quantity (float).
_NAME_OPTIONS = {"gear", "cycle", "solver", "trace", "fit", "holdout", "backend"}
_COUNT_OPTIONS = {"max_steps", "max_iterations", "threads", "threads_per_task", "batch_size", "cases", "segment"}


def _option_value(option: str, text: str) -> Value:
    """An option's value as the Python type the API takes for it."""
    if option in _NAME_OPTIONS:
        return text
    v = typed(text)
    if isinstance(v, int) and not isinstance(v, bool) and option not in _COUNT_OPTIONS:
        return float(v)
    return v
