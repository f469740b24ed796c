"""The Python-API worker of the hostile campaign: one long-lived interpreter with geartherm,
pandas and numpy imported, reading one case per line (JSON) on stdin and answering one line
per case on stdout. The campaign starts one per thread and restarts it when it dies (a crash)
or stops answering (a hang).

A case names a scenario and its arguments as *recipes* (JSON cannot carry NaN, numpy scalars,
DataFrames or arbitrary objects; a recipe such as ``{"r": "np_nan"}`` is built here).

Outcomes: ``ok`` (the call returned; its value is checked: every number finite, every
efficiency in [0, 1], one row per case), ``raised`` with an allowed exception type (a
geartherm error, TypeError, ValueError, OverflowError, OSError) — or a failure class: a Rust
panic surfacing as ``PanicException`` (``panic``), another exception type (``wrong_exit``, the
analogue of a wrong exit code), an exception that changed on its way through a process pool
(``wrong_exit``)."""
import concurrent.futures as cf
import json
import math
import os
import pickle
import re
import sys
import traceback

import numpy as np
import pandas as pd

import geartherm

ALLOWED = (geartherm.GearthermError, TypeError, ValueError, OverflowError, OSError)
_POOL = None


def build(x):
    """A Python object from a recipe."""
    if isinstance(x, dict) and "r" in x and len(x) == 1:
        r = x["r"]
        return {
            "nan": math.nan, "inf": math.inf, "-inf": -math.inf, "none": None, "object": object(),
            "np_nan": np.float64("nan"), "np_int": np.int64(7), "np_float": np.float32(1450.0),
            "big_int": 2 ** 80, "neg_big_int": -(2 ** 80), "bytes": b"fva_3a", "set": {1.0}, "complex": 1 + 2j,
            "neg_zero": -0.0, "df": pd.DataFrame({"a": [1.0, math.nan]}), "series": pd.Series([1450.0, math.nan]),
            "empty_df": pd.DataFrame(), "ndarray": np.array([1000.0, math.nan]), "tuple": (1.0, 2.0),
            "path_dir": "/", "dev_null": "/dev/null", "nul": "a\x00b", "long": "x" * 100000,
            "np_array_2d": np.ones((2, 2)), "bool": True, "frame_params": pd.DataFrame(
                {"path": ["lubrication.oil_level_mm"], "range": [[30.0, 50.0]]}),
        }[r]
    if isinstance(x, dict):
        return {k: build(v) for k, v in x.items()}
    if isinstance(x, list):
        return [build(v) for v in x]
    return x


def finite_json(v, path=""):
    """Paths of non-finite numbers and of efficiencies outside [0, 1] in a returned value."""
    bad = []
    if isinstance(v, dict):
        for k, x in v.items():
            if "efficiency" in str(k) and isinstance(x, float) and not (0.0 <= x <= 1.0):
                bad.append(f"{path}.{k} = {x} (efficiency)")
            bad += finite_json(x, f"{path}.{k}")
    elif isinstance(v, (list, tuple)):
        for i, x in enumerate(v):
            bad += finite_json(x, f"{path}[{i}]")
    elif isinstance(v, float) and not math.isfinite(v):
        bad.append(f"{path} = {v}")
    return bad


def frame_problems(df):
    """Non-finite cells of a returned DataFrame, but for an efficiency, which is blank (NaN)
    where no power flows."""
    num = df.select_dtypes(include=[np.number])
    cols = [c for c in num.columns if "efficiency" not in str(c)]
    bad = [f"column {c} not finite" for c in cols if not np.isfinite(num[c].to_numpy(dtype=float)).all()]
    for c in num.columns:
        if "efficiency" in str(c):
            e = num[c].to_numpy(dtype=float)
            e = e[~np.isnan(e)]
            if ((e < 0.0) | (e > 1.0)).any():
                bad.append(f"column {c} outside [0, 1] (efficiency)")
    return bad


def check_value(value, scenario):
    if isinstance(value, pd.DataFrame):
        if scenario == "study":
            ok = value[value["status"] == "ok"] if "status" in value else value
            probs = frame_problems(ok)
            if "case" in value and value["case"].duplicated().any():
                probs.append("a case appears twice")
            return probs
        return frame_problems(value)
    if isinstance(value, geartherm.RunResult):
        probs = finite_json(value.summary)
        if value.timeseries is not None:
            probs += frame_problems(value.timeseries)
        return probs
    return finite_json(value)


def call(scenario, a):
    fzg = os.path.join(a["root"], "models", "fzg_c.toml")
    if scenario == "load":
        return geartherm.Model.load(build(a["path"]))
    if scenario == "from_text":
        return geartherm.Model.from_text(build(a["text"]), build(a.get("name", "m.toml")))
    base = geartherm.Model.load(os.path.join(a["root"], "models", a.get("model", "fzg_c.toml")))
    if scenario == "override":
        return base.override(build(a["values"]))
    m = base.override(build(a["values"])) if a.get("values") else base
    if scenario in ("losses", "steady", "map", "rating", "run"):
        return getattr(m, scenario)(*build(a.get("args", [])), **build(a.get("kwargs", {})))
    if scenario == "study":
        return geartherm.study(build(a.get("model_arg", fzg)), build(a["parameters"]), build(a.get("job")),
                               build(a.get("sampling")), **build(a.get("kwargs", {})))
    raise ValueError(f"unknown scenario {scenario}")


def pool():
    global _POOL
    if _POOL is None:
        _POOL = cf.ProcessPoolExecutor(max_workers=1)
    return _POOL


def through_pool(scenario, a):
    """The same call in a pool process: the same outcome, the same exception type, message and
    attributes on this side."""
    here = outcome_of(scenario, a)
    try:
        there = pool().submit(remote, scenario, a).result(timeout=60)
    except cf.process.BrokenProcessPool:
        global _POOL
        _POOL = None
        return {"classes": ["crash"], "detail": "the pool process died"}
    except Exception as e:  # an exception that could not travel back
        return {"classes": ["wrong_exit"], "detail": f"through the pool: {type(e).__name__}: {e}"}
    if here != there:
        return {"classes": ["wrong_exit"], "detail": f"in process {here} vs through a pool {there}"}
    return here_result(scenario, a)


def remote(scenario, a):
    """Runs in the pool process: the call's outcome, with the exception itself pickled back."""
    try:
        v = call(scenario, a)
        return ("ok", type(v).__name__)
    except BaseException as e:
        # The exception object crosses the process boundary; its type, message and key path
        # must arrive intact.
        e2 = pickle.loads(pickle.dumps(e))
        return ("raised", type(e2).__name__, plain(str(e2)), getattr(e2, "path", None), getattr(e2, "problems", None))


def outcome_of(scenario, a):
    try:
        v = call(scenario, a)
        return ("ok", type(v).__name__)
    except BaseException as e:
        return ("raised", type(e).__name__, plain(str(e)), getattr(e, "path", None), getattr(e, "problems", None))


def plain(message):
    """A message without object addresses (`<object object at 0x7f…>` differs between processes)."""
    return re.sub(r"0x[0-9a-f]+", "0x…", message)


def here_result(scenario, a):
    try:
        v = call(scenario, a)
    except ALLOWED as e:
        return {"outcome": "raised", "type": type(e).__name__, "message": str(e)[:300], "classes": []}
    except BaseException as e:
        cls = "panic" if type(e).__name__ == "PanicException" else "wrong_exit"
        return {"outcome": "raised", "type": type(e).__name__, "classes": [cls],
                "detail": f"{type(e).__name__}: {e}"[:400] + traceback.format_exc()[-400:]}
    probs = check_value(v, scenario)
    kind = lambda p: "efficiency" if "(efficiency)" in p else "stray" if "twice" in p else "non_finite"
    classes = sorted({kind(p) for p in probs})
    return {"outcome": "ok", "classes": classes, "detail": "; ".join(probs[:3])}


def main():
    for line in sys.stdin:
        case = json.loads(line)
        try:
            if case.get("pool"):
                r = through_pool(case["scenario"], case["args"])
            else:
                r = here_result(case["scenario"], case["args"])
        except BaseException as e:  # the harness itself
            r = {"classes": ["wrong_exit"], "detail": f"harness: {type(e).__name__}: {e}"}
        r["id"] = case["id"]
        sys.stdout.write(json.dumps(r, default=str) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
