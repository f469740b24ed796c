"""CSV text → pandas (or polars) frames with the dtypes of docs/outputs.md: every measured
quantity float64 whatever its values (a column of zeros stays float), names and flags as strings
and booleans, counts as nullable integers. The same reader serves a fresh result and a file read
back, so the two compare equal."""

from __future__ import annotations

import io
import warnings
from typing import Any, Dict, Iterable, Mapping, Optional, Sequence

from .errors import RangeWarning

# Text columns of every table; other columns are numbers unless a table says otherwise.
TEXT = {"gear", "case", "job", "status", "message"}
BOOL = {"converged"}
INT = {"sample", "iterations", "lockup"}


def frame(csv_text: str, text: Iterable[str] = (), backend: str = "pandas") -> Any:
    """A DataFrame of ``csv_text`` with stable dtypes; ``text`` names more string columns (a
    study's text parameters)."""
    import pandas as pd

    header = csv_text.split("\n", 1)[0]
    names = next(iter(__import__("csv").reader([header]))) if header else []
    text = set(text) | TEXT
    dtype: Dict[str, Any] = {}
    for n in names:
        if n in text:
            dtype[n] = object
        elif n in BOOL:
            dtype[n] = object
        elif n in INT:
            dtype[n] = "Int64"
        else:
            dtype[n] = "float64"
    kw: Dict[str, Any] = {"dtype": dtype, "keep_default_na": False, "na_values": {n: [""] for n in names if n not in text}}
    # Numbers must come back exactly as written (shortest round-trip form): pandas < 3 needs
    # float_precision="round_trip" for that; from pandas 3 it is the default.
    if int(pd.__version__.split(".")[0]) < 3:
        kw["float_precision"] = "round_trip"
    df = pd.read_csv(io.StringIO(csv_text), **kw)
    for n in names:
        if n in BOOL:
            df[n] = df[n].map({"true": True, "false": False}).astype("boolean")
        elif n in text:
            df[n] = df[n].astype(str)
    if backend == "polars":
        import polars as pl

        return pl.from_pandas(df)
    if backend != "pandas":
        raise ValueError(f"backend={backend!r}: 'pandas' or 'polars'")
    return df


def warn_ranges(items: Optional[Sequence[Mapping[str, Any]]], stacklevel: int = 3) -> None:
    """The range warnings of one result as one :class:`RangeWarning` on one line: how many, the
    first in full, the items of the others (every one stays in the result's ``warnings``)."""
    items = list(items or ())
    if not items:
        return
    first = items[0]
    text = f"{first.get('item')}: {first.get('range')} ({first.get('seen')})"
    if len(items) > 1:
        others = list(dict.fromkeys(str(w.get("item")) for w in items[1:]))
        text += f"; also {', '.join(others)}"
    line = " ".join(f"{len(items)} range warning(s): {text} (all in the result's warnings)".split())
    warnings.warn(RangeWarning(line), stacklevel=stacklevel)


def html_table(title: str, rows: Iterable[Sequence[Any]]) -> str:
    """A small two-column HTML table (for ``_repr_html_``)."""
    import html

    body = "".join(
        f"<tr><th style='text-align:left'>{html.escape(str(k))}</th><td style='text-align:left'>{html.escape(str(v))}</td></tr>"
        for k, v in rows
    )
    return f"<div><b>{html.escape(title)}</b><table>{body}</table></div>"
