"""Types of the public API: what the functions take and return (``mypy --strict`` checks the
docs' examples against them)."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Dict, List, Mapping, Sequence, Union

if TYPE_CHECKING:
    import pandas
    import polars

#: A file path.
PathLike = Union[str, "os.PathLike[str]"]

#: A drive or rig cycle: a bundled cycle's name, a CSV file, or a DataFrame with a cycle file's
#: columns.
CycleLike = Union[str, "os.PathLike[str]", "pandas.DataFrame", "polars.DataFrame"]

#: A value of a model key (what ``Model.override`` takes): a TOML scalar, an array, a table.
TomlValue = Union[bool, int, float, str, Sequence["TomlValue"], Mapping[str, "TomlValue"]]

#: A JSON document as the result dicts hold it.
Json = Union[None, bool, int, float, str, List["Json"], Dict[str, "Json"]]

#: A study parameter's specification (``{"range": [lo, hi]}``, ``{"values": [...]}``,
#: ``{"scale": [lo, hi]}``, ``"levels"``, ``"path"``; checked when the study is built).
ParameterSpec = Mapping[str, object]

#: A study's job (``{"kind": "run", "cycles": [...], "options": {...}}``, ...) or sampling plan.
JobSpec = Mapping[str, object]
