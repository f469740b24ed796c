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
from typing import Any, List, Optional, Sequence, Tuple

__all__ = [
    "GearthermError",
    "ModelError",
    "InputError",
    "SolveError",
    "RangeWarning",
]

Problem = Tuple[str, str, str]


class GearthermError(Exception):
    """Base class of geartherm's errors.

    Attributes
    ----------
    message : str
        The message, as the CLI prints it (file, key path, value, allowed range).
    path : str or None
        Key path of the first problem (``"lubrication.oil_level_mm"``), or the option's name.
    value : str or None
        The value given there, as text.
    allowed : str or None
        What is allowed there (a range with its unit, a list of names).
    problems : list of (path, value, allowed)
        Every problem found (a model check reports all of them at once).
    """

    def __init__(
        self,
        message: str,
        *,
        path: Optional[str] = None,
        value: Optional[str] = None,
        allowed: Optional[str] = None,
        problems: Sequence[Problem] = (),
    ) -> None:
        super().__init__(message)
        self.message = message
        self.problems: List[Problem] = [tuple(p) for p in problems]  # type: ignore[misc]
        first = self.problems[0] if self.problems else (None, None, None)
        self.path = path if path is not None else first[0]
        self.value = value if value is not None else first[1]
        self.allowed = allowed if allowed is not None else first[2]

    def __reduce__(self) -> Any:
        fields = {"path": self.path, "value": self.value, "allowed": self.allowed, "problems": self.problems}
        return (_rebuild, (type(self), self.message, fields))

    def __str__(self) -> str:
        return self.message


def _rebuild(cls: type, message: str, fields: dict) -> GearthermError:
    return cls(message, **fields)


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


def _from_native(kind: str, message: str, problems: Sequence[Problem], file: Optional[str]) -> BaseException:
    """The exception for a failure reported by the native module (called from Rust)."""
    if kind == "not_found":
        return FileNotFoundError(_errno.ENOENT, message, file) if file else FileNotFoundError(_errno.ENOENT, message)
    if kind == "io":
        return OSError(_errno.EIO, message, file) if file else OSError(message)
    cls = {"model": ModelError, "input": InputError, "solve": SolveError}.get(kind, GearthermError)
    return cls(message, problems=problems)
