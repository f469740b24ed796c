"""Figures with matplotlib (an optional extra: ``pip install "geartherm[plot]"``): a run's
temperatures, losses and energies, and a study's Pareto front and main effects. Axes carry units
and readable scales (°C, kW, kJ/MJ); every function returns the matplotlib Figure."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

__all__ = ["run_figure", "pareto", "main_effects", "pareto_front"]


def _plt():
    try:
        import matplotlib

        if matplotlib.get_backend().lower() not in ("agg",) and not _interactive():
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - the message is the point
        raise ImportError('geartherm plots need matplotlib: pip install "geartherm[plot]"') from e
    return plt


def _interactive() -> bool:
    import sys

    return "ipykernel" in sys.modules or hasattr(sys, "ps1")


def _unit(column: str) -> Tuple[str, float, str]:
    """(label, scale, unit) of a column named by the schema's unit suffix."""
    name = column
    for suffix, (scale, unit) in {
        "_j": (1.0, "J"),
        "_w": (1.0, "W"),
        "_c": (1.0, "°C"),
    }.items():
        if column.endswith(suffix):
            name = column[: -len(suffix)]
            return name.replace("_", " "), scale, unit
    return name.replace("_", " "), 1.0, ""


def _factor(values, unit: str) -> Tuple[float, str]:
    """The readable multiple of a unit for these values (kJ, MJ, kW): (factor, unit)."""
    import numpy as np

    v = np.asarray(values, dtype=float)
    top = np.nanmax(np.abs(v)) if v.size and np.isfinite(v).any() else 0.0
    if unit in ("J", "W"):
        for f, p in ((1e6, "M"), (1e3, "k")):
            if top >= f:
                return f, p + unit
    return 1.0, unit


def _scaled(values, unit: str) -> Tuple[Any, str]:
    """Values in a readable multiple of their unit."""
    import numpy as np

    f, u = _factor(values, unit)
    return np.asarray(values, dtype=float) / f, u


def _axis(ax, column: str, values, which: str = "y") -> float:
    """Label an axis with the column's name and readable unit; the factor values divide by."""
    label, _, unit = _unit(column)
    f, u = _factor(values, unit)
    (ax.set_ylabel if which == "y" else ax.set_xlabel)(f"{label} [{u}]" if u else label)
    return f


def run_figure(result, kind: str = "all"):
    """The run report's figures of a :class:`~geartherm.RunResult` (see ``RunResult.plot``)."""
    plt = _plt()
    kinds = ["temperatures", "losses", "energy"] if kind == "all" else [kind]
    if any(k not in ("temperatures", "losses", "energy") for k in kinds):
        raise ValueError(f"kind={kind!r}: 'all', 'temperatures', 'losses' or 'energy'")
    ts = result.timeseries
    if ts is None and kind != "energy":
        kinds = ["energy"]
    fig, axes = plt.subplots(len(kinds), 1, figsize=(9, 3.2 * len(kinds)), squeeze=False)
    s = result.summary
    for ax, k in zip(axes[:, 0], kinds):
        if k == "temperatures":
            nodes = [n["name"] for n in s["nodes"] if not n["boundary"]]
            for n in nodes:
                ax.plot(ts["time_s"], ts[f"temp_{n}_c"], label=n)
            ax.set_ylabel("temperature [°C]")
            ax.set_xlabel("time [s]")
            ax.legend(fontsize=7, ncol=3)
        elif k == "losses":
            cols = [c for c in _source_columns(ts.columns) if ts[c].abs().max() > 0]
            scale = 1e3 if ts[cols].sum(axis=1).max() >= 1e3 else 1.0
            ax.stackplot(ts["time_s"], *[ts[c] / scale for c in cols], labels=[c[5:-2] for c in cols])
            ax.set_ylabel(f"loss [{'kW' if scale == 1e3 else 'W'}]")
            ax.set_xlabel("time [s]")
            ax.legend(fontsize=7, ncol=4, loc="upper left")
        else:
            e = {k2: v for k2, v in s["energy_lost_j"].items() if k2 != "total" and v}
            v, u = _scaled(list(e.values()), "J")
            ax.barh(list(e.keys()), v)
            ax.set_xlabel(f"energy lost [{u}]")
    fig.suptitle(f"{s.get('model')} — {s.get('cycle')}")
    fig.tight_layout()
    return fig


def _source_columns(columns: Sequence[str]) -> List[str]:
    from . import SOURCES

    return [f"loss_{src}_w" for src in SOURCES if f"loss_{src}_w" in columns]


def pareto_front(df, a: str, b: str):
    """The rows of ``df`` (status ``ok``) not dominated in (``a``, ``b``), both minimised,
    sorted by ``a``."""
    ok = df[df["status"] == "ok"].dropna(subset=[a, b]).sort_values([a, b])
    front, best = [], float("inf")
    for i, r in ok.iterrows():
        if r[b] < best:
            front.append(i)
            best = r[b]
    return ok.loc[front]


def pareto(df, a: str, b: str, *, label: str = "case", color_by: Optional[str] = None, ax=None):
    """Scatter of every case in (``a``, ``b``) with the Pareto front (both minimised) drawn
    and its cases labelled (by the ``label`` column); ``color_by`` colours by a parameter."""
    plt = _plt()
    fig = ax.figure if ax is not None else plt.figure(figsize=(7, 5))
    ax = ax if ax is not None else fig.add_subplot()
    ok = df[df["status"] == "ok"]
    fa = _axis(ax, a, ok[a], "x")
    fb = _axis(ax, b, ok[b], "y")
    x = ok[a].to_numpy(dtype=float) / fa
    y = ok[b].to_numpy(dtype=float) / fb
    if color_by is not None:
        for val in sorted(ok[color_by].astype(str).unique()):
            m = (ok[color_by].astype(str) == val).to_numpy()
            ax.scatter(x[m], y[m], s=10, alpha=0.6, label=val)
        ax.legend(title=color_by, fontsize=7)
    else:
        ax.scatter(x, y, s=10, alpha=0.5, color="0.5")
    f = pareto_front(df, a, b)
    fx = f[a].to_numpy(dtype=float) / fa
    fy = f[b].to_numpy(dtype=float) / fb
    ax.plot(fx, fy, "k-o", ms=4, lw=1, label="Pareto front")
    for xi, yi, t in zip(fx, fy, f[label].astype(str)):
        ax.annotate(t, (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_title("Pareto front")
    fig.tight_layout()
    return fig


def main_effects(df, outputs: Sequence[str], parameters: Optional[Sequence[str]] = None, *, color_by: Optional[str] = None):
    """One panel per (output, numeric parameter): every case as a point, coloured by
    ``color_by`` (a text parameter such as the oil: one band per value), with the mean per
    colour."""
    plt = _plt()
    ok = df[df["status"] == "ok"]
    first = list(df.columns).index("job") + 1
    last = list(df.columns).index("status")
    params = list(parameters) if parameters is not None else [c for c in df.columns[first:last] if ok[c].dtype.kind == "f"]
    fig, axes = plt.subplots(len(outputs), len(params), figsize=(3.4 * len(params), 2.8 * len(outputs)), squeeze=False)
    groups = sorted(ok[color_by].astype(str).unique()) if color_by else [None]
    for i, o in enumerate(outputs):
        for j, p in enumerate(params):
            ax = axes[i, j]
            fo = _axis(ax, o, ok[o], "y")
            for g in groups:
                sub = ok if g is None else ok[ok[color_by].astype(str) == g]
                ax.scatter(sub[p], sub[o].to_numpy(dtype=float) / fo, s=6, alpha=0.5, label=g)
            ax.set_xlabel(p, fontsize=7)
            if i == 0 and j == 0 and color_by:
                ax.legend(title=color_by, fontsize=6)
    fig.tight_layout()
    return fig


def calibration_figure(fit: Any) -> Any:
    """Measured (points) and simulated (lines) temperature of every channel of a calibration's
    ``fit.csv`` over time, held-out rows shaded, and the residuals (K) below."""
    plt = _plt()
    import numpy as np

    nodes = [c[: -len("_measured_c")] for c in fit.columns if c.endswith("_measured_c")]
    t = np.asarray(fit["time_s"], dtype=float)
    scale, unit = (3600.0, "h") if t.size and t[-1] - t[0] > 7200 else (1.0, "s")
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), height_ratios=[3, 1])
    held = np.asarray(fit["held_out"], dtype=float) > 0 if "held_out" in fit.columns else np.zeros(t.size, bool)
    for ax in (top, bottom):
        if held.any():
            ax.fill_between(t / scale, 0, 1, where=held, color="0.9", transform=ax.get_xaxis_transform(), label=None)
    for n in nodes:
        line = top.plot(t / scale, fit[f"{n}_simulated_c"], label=f"{n} simulated")[0]
        top.plot(t / scale, fit[f"{n}_measured_c"], ".", ms=3, color=line.get_color(), label=f"{n} measured")
        bottom.plot(t / scale, fit[f"{n}_residual_k"], color=line.get_color(), label=n)
    top.set_ylabel("temperature (°C)")
    top.legend(fontsize="small")
    bottom.set_ylabel("residual (K)")
    bottom.set_xlabel(f"time ({unit})")
    top.set_title("Calibration: measured and simulated" + (" (held-out rows shaded)" if held.any() else ""))
    fig.tight_layout()
    return fig
