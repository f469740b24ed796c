#!/usr/bin/env python3
"""Peer comparison: geartherm vs an independent scipy solve_ivp implementation of
the FZG C scene over WLTC. Run from the repository root:

    pip install --user numpy scipy
    python3 benches/peer/compare.py            # full run (a few minutes on 2 cores)
    python3 benches/peer/compare.py --quick    # 1 repeat, fewer tolerances

Writes benches/peer/results.csv and benches/peer/results.md. Work files go to a temporary
directory (removed at the end).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fzg_peer as peer  # noqa: E402



def wait_exe(exe: str, seconds: float = 300.0):
    """The lead may rebuild the binary while we run: wait for it to reappear."""
    t0 = time.time()
    while not os.access(exe, os.X_OK):
        if time.time() - t0 > seconds:
            raise SystemExit(f"{exe} missing (build it with cargo build --release)")
        time.sleep(2.0)


def run_geartherm(root, exe, model, out, solver, rtol, atol):
    """One geartherm run; returns (summary, process wall time, temperatures (°C) on the 1 Hz grid)."""
    for attempt in range(5):
        wait_exe(exe)
        t0 = time.perf_counter()
        p = subprocess.run([exe, "run", model, "--cycle", "wltc", "--out", out, "--solver", solver,
                            "--rtol", repr(rtol), "--atol", repr(atol), "--json", "--quiet"],
                           cwd=root, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode == 0:
            break
        if attempt == 4:
            raise RuntimeError(f"geartherm failed: {p.stderr}")
        time.sleep(3.0)
    js = json.loads(p.stdout)
    with open(os.path.join(out, "timeseries.csv")) as f:
        rows = list(csv.DictReader(f))
    return js, wall, rows


def temps_of(rows, names):
    return np.array([[float(r[f"temp_{n}_c"]) for n in names] for r in rows])


def median_runs(fn, repeats):
    outs = [fn() for _ in range(repeats)]
    return outs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default=".")
    ap.add_argument("--exe", default="target/release/geartherm")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    exe = args.exe if os.path.isabs(args.exe) else os.path.join(root, args.exe)
    wait_exe(exe)
    reps = 1 if args.quick else args.repeats
    tmp = tempfile.mkdtemp(prefix="geartherm_peer_")
    try:
        _main(root, exe, reps, args.quick, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _main(root, exe, reps, quick, tmp):
    # the FZG C model without its bearings and seals, which the peer does not model:
    # both tools integrate this same network
    model = peer.peer_model(os.path.join(root, "models", "fzg_c.toml"),
                                  os.path.join(tmp, "fzg_c.toml"))
    scene = peer.Scene(root, exe, model=model)
    names = scene.node_names
    sched = peer.schedule(scene, os.path.join(root, "models", "cycles", "wltc_class3b.csv"))
    print(f"pocketing K = {scene.pocket_k:.10e} m^5 (from geartherm losses; physics.md: "
          f"{peer.POCKET_K_DOC:.5e})", flush=True)

    # ---- 1. loss check against `geartherm losses` ------------------------------------------
    rows = peer.check_losses(scene, exe, verbose=False)
    loss_check = {}
    for r in rows:
        loss_check[r[3]] = max(loss_check.get(r[3], 0.0), abs(r[6]))
    print("loss check (max |rel| over 7 points):", loss_check, flush=True)

    # ---- 2. references ---------------------------------------------------------------------
    gref = {}
    for rt in (1e-10, 1e-12):
        out = os.path.join(tmp, f"ref_{rt:g}")
        js, wall, trows = run_geartherm(root, exe, model, out, "esdirk34", rt, rt)
        gref[rt] = (js, temps_of(trows, names))
        print(f"geartherm esdirk34 rtol {rt:g}: {js['steps']} steps, {js['wall_time_s']:.4f} s", flush=True)
    g_ref_js, g_ref_T = gref[1e-12]
    e_ref = g_ref_js["energy_lost_j"]["total"]

    peer_ref = {}
    for meth, rt in (("Radau", 1e-12), ("BDF", 1e-12)):
        r = peer.run(scene, sched, meth, rt, rt)
        peer_ref[meth] = r
        print(f"peer {meth} rtol {rt:g}: {r['wall']:.2f} s", flush=True)
    p_ref_T = peer_ref["Radau"]["states"][:, :scene.n] - peer.KELVIN
    p_ref_E = peer_ref["Radau"]["states"][-1, scene.n:scene.n + scene.m_items].sum()
    agree = {
        "geartherm 1e-12 vs peer Radau 1e-12": np.abs(g_ref_T - p_ref_T).max(),
        "geartherm 1e-10 vs peer Radau 1e-12": np.abs(gref[1e-10][1] - p_ref_T).max(),
        "geartherm 1e-10 vs geartherm 1e-12": np.abs(gref[1e-10][1] - g_ref_T).max(),
        "peer BDF 1e-12 vs peer Radau 1e-12":
            np.abs(peer_ref["BDF"]["states"][:, :scene.n] - peer.KELVIN - p_ref_T).max(),
        "geartherm 1e-12 vs peer Radau 1e-12, final": np.abs(g_ref_T[-1] - p_ref_T[-1]).max(),
    }
    agree_energy = abs(p_ref_E - e_ref) / e_ref
    for k, v in agree.items():
        print(f"agreement {k}: {v:.3e} K", flush=True)
    print(f"energy lost: geartherm {e_ref:.6f} J, peer {p_ref_E:.6f} J, rel {agree_energy:.2e}", flush=True)
    REF = g_ref_T  # errors are measured against geartherm esdirk34 at rtol = atol = 1e-12

    def errs(T):
        d = np.abs(T - REF)
        return d.max(), d[-1].max()

    results = []
    # ---- 3. geartherm sweep ----------------------------------------------------------------
    g_rtols = (1e-4, 1e-6, 1e-8) if quick else (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
    for solver in ("ros3", "tr-bdf2", "esdirk34", "bdf"):
        for rt in g_rtols:
            runs = []
            for k in range(reps):
                out = os.path.join(tmp, f"g_{solver}_{rt:g}_{k}")
                runs.append(run_geartherm(root, exe, model, out, solver, rt, rt))
            js, _, trows = runs[0]
            T = temps_of(trows, names)
            emax, efin = errs(T)
            results.append(dict(
                tool="geartherm", method=solver, rtol=rt,
                wall_s=statistics.median(r[0]["wall_time_s"] for r in runs),
                process_s=statistics.median(r[1] for r in runs),
                steps=js["steps"], rhs_evals=js["stats"]["rhs_evals"],
                max_dT_K=emax, final_dT_K=efin,
                energy_J=js["energy_lost_j"]["total"],
                energy_rel=(js["energy_lost_j"]["total"] - e_ref) / e_ref))
            print(results[-1], flush=True)

    # ---- 4. peer sweep ---------------------------------------------------------------------
    p_rtols = (1e-4, 1e-6, 1e-8) if quick else (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
    for meth in ("BDF", "Radau", "LSODA"):
        for rt in p_rtols:
            runs = [peer.run(scene, sched, meth, rt, rt) for _ in range(reps)]
            r0 = runs[0]
            T = r0["states"][:, :scene.n] - peer.KELVIN
            emax, efin = errs(T)
            e = r0["states"][-1, scene.n:scene.n + scene.m_items].sum()
            results.append(dict(
                tool="peer (scipy)", method=meth, rtol=rt,
                wall_s=statistics.median(r["wall"] for r in runs), process_s=float("nan"),
                steps=float("nan"), rhs_evals=r0["nfev"],
                max_dT_K=emax, final_dT_K=efin, energy_J=e, energy_rel=(e - e_ref) / e_ref))
            print(results[-1], flush=True)

    # ---- 5. equal-error speed ratios -------------------------------------------------------
    ratios = []
    for g in [r for r in results if r["tool"] == "geartherm"]:
        for meth in ("BDF", "Radau", "LSODA"):
            ps = [r for r in results if r["tool"] != "geartherm" and r["method"] == meth]
            ok = [r for r in ps if r["max_dT_K"] <= g["max_dT_K"]]
            best = min(ok, key=lambda r: r["wall_s"]) if ok else None
            # log-log interpolation of the peer's time at geartherm's error
            pts = sorted((math.log(r["max_dT_K"]), math.log(r["wall_s"])) for r in ps if r["max_dT_K"] > 0)
            xs = [p[0] for p in pts]
            x = math.log(g["max_dT_K"])
            interp = None
            if xs[0] <= x <= xs[-1]:
                interp = math.exp(np.interp(x, xs, [p[1] for p in pts]))
            ratios.append(dict(
                g_method=g["method"], g_rtol=g["rtol"], g_err=g["max_dT_K"], g_wall=g["wall_s"],
                g_proc=g["process_s"], p_method=meth,
                p_best=(best["rtol"], best["wall_s"], best["max_dT_K"]) if best else None,
                p_interp=interp))

    # ---- 6. write --------------------------------------------------------------------------
    with open(os.path.join(HERE, "results.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["tool", "method", "rtol", "atol", "wall_s", "process_s", "steps", "rhs_evals",
                    "max_abs_dT_K", "final_abs_dT_K", "energy_lost_J", "energy_lost_rel_vs_ref"])
        for r in results:
            w.writerow([r["tool"], r["method"], f"{r['rtol']:g}", f"{r['rtol']:g}", f"{r['wall_s']:.6g}",
                        "" if math.isnan(r["process_s"]) else f"{r['process_s']:.6g}",
                        "" if isinstance(r["steps"], float) else r["steps"], r["rhs_evals"],
                        f"{r['max_dT_K']:.3e}", f"{r['final_dT_K']:.3e}", f"{r['energy_J']:.6f}",
                        f"{r['energy_rel']:.3e}"])
    L = []
    L.append("# Peer comparison: geartherm vs scipy `solve_ivp` on FZG C over WLTC\n")
    L.append(f"Generated by `python3 benches/peer/compare.py{' --quick' if quick else ''}` on "
             f"{time.strftime('%Y-%m-%d %H:%M')}; {reps} repeat(s) per point, median wall time. "
             f"Python {sys.version.split()[0]}, numpy {np.__version__}, scipy "
             f"{__import__('scipy').__version__}. Machine: {os.cpu_count()} cores, shared.\n")
    L.append("atol = rtol for every run (geartherm: atol on temperatures in K, energies atol × mean "
             "capacity; the peer uses the same scaling). Errors: max over the five nodes and the "
             "1801 points of the 1 Hz grid of |T − T_ref|, and the same at t = 1800 s; reference = "
             "geartherm ESDIRK34 at rtol = atol = 1e-12 (agreement with the peer below). "
             "geartherm wall = `summary.json` `wall_time_s` (integration only); process = whole "
             "`geartherm run` process (parse, compile, integrate, write CSV). Peer wall = the "
             "`solve_ivp` loop (scene set up beforehand, like geartherm's compile).\n")
    L.append("## Loss check (peer equations vs `geartherm losses`, 7 operating points, 23–110 °C)\n")
    L.append("| item | max relative difference |\n|---|---|")
    for k, v in loss_check.items():
        L.append(f"| {k} | {v:.1e} |")
    L.append("\n(pocketing K is geartherm's compiled number, so that row checks only P = z1 ρ ω³ K/(4π) "
             "and the density mix; churning, sliding and the oil are independent re-implementations.)\n")
    L.append("## Reference agreement (independent implementations)\n")
    L.append("| pair | max \\|ΔT\\| over the 1 Hz grid (K) |\n|---|---|")
    for k, v in agree.items():
        L.append(f"| {k} | {v:.2e} |")
    L.append(f"| energy lost, geartherm 1e-12 vs peer Radau 1e-12 (relative) | {agree_energy:.1e} |")
    L.append(f"\nReference run cost: geartherm ESDIRK34 1e-12 {g_ref_js['wall_time_s']:.3f} s "
             f"({g_ref_js['steps']} steps); peer Radau 1e-12 {peer_ref['Radau']['wall']:.1f} s, "
             f"BDF 1e-12 {peer_ref['BDF']['wall']:.1f} s.\n")
    L.append("## Work-precision table\n")
    L.append("| tool | method | rtol | wall (s) | process (s) | max \\|ΔT\\| (K) | final \\|ΔT\\| (K) | "
             "energy lost (J) | vs ref |\n|---|---|---|---|---|---|---|---|---|")
    for r in results:
        L.append(f"| {r['tool']} | {r['method']} | {r['rtol']:g} | {r['wall_s']:.4g} | "
                 f"{'' if math.isnan(r['process_s']) else format(r['process_s'], '.4g')} | "
                 f"{r['max_dT_K']:.2e} | {r['final_dT_K']:.2e} | {r['energy_J']:.3f} | "
                 f"{r['energy_rel']:+.1e} |")
    L.append(f"\nReference energy lost (geartherm 1e-12): {e_ref:.6f} J.\n")
    L.append("## Speed at equal error\n")
    L.append("For each geartherm run: the fastest peer run of each method whose max |ΔT| is not larger, "
             "and the peer time log-log interpolated at geartherm's error (blank when outside the "
             "peer's measured range).\n")
    L.append("| geartherm | its max \\|ΔT\\| | its wall (s) | peer method | fastest peer run at ≤ that error | "
             "ratio (wall / process) | interpolated ratio (wall / process) |\n|---|---|---|---|---|---|---|")
    for q in ratios:
        if q["p_best"]:
            b = f"rtol {q['p_best'][0]:g}: {q['p_best'][1]:.3f} s ({q['p_best'][2]:.1e} K)"
            rr = f"{q['p_best'][1] / q['g_wall']:.0f}× / {q['p_best'][1] / q['g_proc']:.0f}×"
        else:
            b, rr = "none (peer never as accurate in this sweep)", "> " + \
                f"{max(r['wall_s'] for r in results if r['method'] == q['p_method']) / q['g_wall']:.0f}×"
        ir = f"{q['p_interp'] / q['g_wall']:.0f}× / {q['p_interp'] / q['g_proc']:.0f}×" if q["p_interp"] else ""
        L.append(f"| {q['g_method']} rtol {q['g_rtol']:g} | {q['g_err']:.1e} | {q['g_wall']:.4f} | "
                 f"{q['p_method']} | {b} | {rr} | {ir} |")
    L.append("\n## Notes\n")
    L.append("- geartherm takes about one step per 1 s interval at rtol 1e-4 to 1e-8: the interval ends "
             "are stop times, so at loose tolerances the step size is capped by the output grid "
             "rather than by error control. This is why rtol 1e-4 and 1e-5 give the same result.")
    L.append("- Radau's error at the step ends is tiny: its final |ΔT| is at the reference level at "
             "every rtol. Its 1 Hz grid error comes from scipy's dense output (`t_eval`) inside "
             "multi-second steps over stretches of constant input. That is why its max |ΔT| is not "
             "monotone in rtol.")
    L.append("- scipy's LSODA is Fortran. It is 4–7× faster than scipy's pure-Python BDF/Radau on "
             "this problem, and it is the strongest peer. The peer's cost is mostly Python overhead "
             "per RHS call and per `solve_ivp` call (about 1560 restarts).")
    with open(os.path.join(HERE, "results.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    print("\n".join(L))


if __name__ == "__main__":
    main()
