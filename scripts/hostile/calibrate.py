"""`calibrate` over several traces (family ``calibrate_traces``): two or three generated rig
traces of the helical stage (gaps that cut them into segments, hostile cells, columns missing,
renamed or reordered, a node the model does not have), shared and per-trace `--fit` keys
(`KEY@N`, `KEY@name`, `KEY@*`, unknown traces), priors on the command line and in a priors file
(negative, zero and non-finite widths, unknown traces), `--profile`, `--residuals`, `--rated`,
`--gearbox-kind`, `--segment`, `--holdout`, and `--band-from` a calibration over several traces
(made once per campaign) or a crafted one. Half of the cases write into a directory that holds a
complete previous result set, which a failure must leave byte for byte."""
import atexit
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading

from . import core

LOCK = threading.Lock()

MODEL = "helical_stage.toml"
H = 'thermal.links["oil-housing"].h_w_per_m2k'
M = 'thermal.nodes["housing"].mass_kg'
HOSTILE = ["0", "-1", "1e308", "nan", "inf", "-inf", "x", "", "1e-300", "-0.0", "9999"]
COLUMNS = ["time_s", "input_speed_rpm", "input_torque_nm", "gear", "boundary:ambient", "node:oil",
           "node:housing"]


def gen_trace(rng, mass):
    """A warm-up of the helical stage measured on oil and housing: two segments a day apart
    (sometimes one, sometimes three), hostile cells and columns with small chances."""
    cols = list(COLUMNS)
    r = rng.random()
    if r < 0.05:
        cols.remove(rng.choice(cols[4:]))
    elif r < 0.08:
        cols[rng.randrange(4, len(cols))] = rng.choice(["node:bearing_x", "boundary:sun", "node:oil"])
    elif r < 0.15:
        head, tail = cols[:4], cols[4:]
        rng.shuffle(tail)
        cols = head + tail
    rows, t = [",".join(cols)], 0.0
    # Most traces are clean (the options are what is hostile); a few carry bad cells or times.
    bad_cells = 0.02 if rng.random() < 0.15 else 0.0
    bad_times = [0.0, -60.0, 1e-9] if rng.random() < 0.1 else []
    segments = rng.choice([1, 2, 2, 2, 3])
    n = rng.choice([12, 20, 30])
    tau = 5.0 + mass
    for s in range(segments):
        for k in range(n):
            load = [(3000, 200), (4000, 250), (1500, 100)][(k * 3) // n]
            x = 30.0 + 20.0 * (1.0 - 2.718281828 ** (-k / tau)) + 0.1 * rng.gauss(0, 1)
            good = {"time_s": str(t), "input_speed_rpm": str(load[0]), "input_torque_nm": str(load[1]),
                    "gear": "1", "boundary:ambient": "20", "node:oil": f"{x:.4f}",
                    "node:housing": f"{x - 2:.4f}", "node:bearing_x": "40", "boundary:sun": "20"}
            cells = [good[c] if rng.random() >= bad_cells else rng.choice(HOSTILE) for c in cols]
            rows.append(",".join(cells))
            t += rng.choice([60.0] * 30 + bad_times)
        t += 90_000.0
    return "\n".join(rows) + "\n"


def fit_args(rng, names):
    good = [H, f"{H}=50:5000", f"{M}@*=2:60", f"{M}@0=2:60", f"{M}@{names[-1]}=2:60"]
    bad = [f"{M}=2:60", "losses.multiplier.churning=0.1:10", f"{M}@9", f"{M}@nobody", "thermal.nodes[9].mass_kg",
           'thermal.nodes["oil"].mass_kg@*', f"{H}@*=1e-9:1e9", "losses.stavytskyi_ks=0.2:0.9"]
    out = [rng.choice(good[:2])] if rng.random() < 0.8 else []
    for _ in range(rng.choice([0, 1, 1, 2])):
        out.append(rng.choice(good if rng.random() < 0.75 else bad))
    return [f"--fit={k}" for k in dict.fromkeys(out)]


def prior_args(rng, names, d):
    widths = ["0.5", "0.5", "2", "0", "-1", "nan", "inf", "1e-300", "1e300"]
    keys = [H, f"{M}@*", f"{M}@{names[0]}", f"{M}@1", f"{M}@nobody", f"{M}@7", M, "losses.multiplier.churning"]
    out = []
    for _ in range(rng.choice([0, 0, 0, 1, 1, 2])):
        dist = rng.choice(["normal:20", "lognormal:20", "lognormal:-1", "cauchy:1"])
        out.append(f"--prior={rng.choice(keys)}={dist}:{rng.choice(widths)}")
    if rng.random() < 0.15:
        path = os.path.join(d, "priors.toml")
        sd = rng.choice(["1", "-1", "0", "nan", '"x"'])
        with open(path, "w") as f:
            f.write(f"[[prior]]\nkey = '{rng.choice(keys)}'\ndistribution = 'normal'\nmean = 20\nsd = {sd}\n")
        out += ["--priors", path]
    return out


def option_args(rng, names):
    a = []
    if rng.random() < 0.3:
        a += ["--residuals", rng.choice(["ar1", "ar1-gls", "independent", "ar2"])]
    if rng.random() < 0.2:
        a += [f"--profile={rng.choice([H, f'{M}@*', f'{M}@{names[0]}', f'{M}@nobody', 'x.y'])}"]
    if rng.random() < 0.2:
        a += [f"--rated={rng.choice(['4000:250', '0:1', '1e9:1', '-5:2', 'x', '3000:-100'])}"]
    if rng.random() < 0.15:
        a += ["--gearbox-kind", rng.choice(["wind-turbine", "ship"])]
    if rng.random() < 0.2:
        a += [f"--holdout={rng.choice(['0:600', '0:1e9', '600:300', 'nan:1', '1200:1800'])}"]
    if rng.random() < 0.1:
        a += ["--segment", rng.choice(["all", "0,1", "0", "5", ",", "1,1"])]
    if rng.random() < 0.1:
        a += ["--max-iterations", rng.choice(["1", "3", "0", "5000"])]
    return a


def make_case(i, rng):
    n = rng.choice([1, 2, 2, 2, 3])
    names = ["a", "b", "c"][:n]
    traces = {name: gen_trace(rng, rng.choice([8.0, 11.0, 20.0])) for name in names}
    case = {"id": i, "family": "calibrate_traces", "traces": traces, "names": names,
            "seed": rng.randrange(2 ** 62), "preload": rng.random() < 0.5,
            "band": rng.choice([None, None, None, "template", "crafted"])}
    return case


def template(ctx):
    """A calibration over two traces with a parameter per trace (made once): its directory."""
    with LOCK:
        if not hasattr(ctx, "calibrate_template"):
            ctx.calibrate_template = make_template(ctx)
        return ctx.calibrate_template


def make_template(ctx):
    import random
    d = tempfile.mkdtemp(prefix="hostile_calibrate_tpl_")
    atexit.register(shutil.rmtree, d, True)
    rng = random.Random(5)
    paths = []
    for name, mass in (("a", 11.0), ("b", 20.0)):
        p = os.path.join(d, f"{name}.csv")
        text = gen_trace(rng, mass)
        while text.split("\n", 1)[0] != ",".join(COLUMNS) or not clean(text):
            text = gen_trace(rng, mass)
        with open(p, "w") as f:
            f.write(text)
        paths.append(p)
    out = os.path.join(d, "cal")
    args = [ctx.bin, "calibrate", os.path.join(ctx.root, "models", MODEL), "--trace", paths[0], "--trace",
            paths[1], f"--fit={H}", f"--fit={M}@*=2:60", "--out", out]
    p = subprocess.run(args, capture_output=True)
    if p.returncode != 0:
        print(f"calibrate template failed: {p.stderr.decode(errors='replace')[-300:]}", file=sys.stderr)
        return None
    return out


def clean(text):
    """Every cell a number (or the gear), every time after the one before."""
    rows = [r.split(",") for r in text.strip().split("\n")[1:]]
    try:
        times = [float(r[0]) for r in rows]
        ok = all(float(x) == float(x) and abs(float(x)) < 1e6 for r in rows for x in r[1:3] + r[4:])
    except ValueError:
        return False
    return ok and all(b > a for a, b in zip(times, times[1:]))


def crafted_band(rng, tpl, d):
    doc = json.load(open(os.path.join(tpl, "calibration.json")))
    k = rng.random()
    if k < 0.3:
        doc["parameters"][rng.randrange(len(doc["parameters"]))]["key_path"] += rng.choice(["@zz", "@*", "x"])
    elif k < 0.5:
        doc["covariance"] = doc["covariance"][:1]
    elif k < 0.7:
        doc["parameters"][-1]["value"] = rng.choice([-1.0, 1e300, 0.0])
    elif k < 0.85:
        doc["channels"] = doc["channels"][:1]
    else:
        doc["fit"]["t975"] = rng.choice([-1.0, 0.0, 1e300])
    path = os.path.join(d, "crafted.json")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def build_args(case, ctx, d):
    import random
    rng = random.Random(case["seed"])
    paths = []
    for name in case["names"]:
        p = os.path.join(d, f"{name}.csv")
        with open(p, "w") as f:
            f.write(case["traces"][name])
        paths.append(p)
    if rng.random() < 0.05 and len(paths) > 1:
        paths[1] = paths[0]
    args = ["calibrate", os.path.join(ctx.root, "models", MODEL)]
    for p in paths:
        args += ["--trace", p]
    args += fit_args(rng, case["names"]) + prior_args(rng, case["names"], d) + option_args(rng, case["names"])
    tpl = template(ctx) if case["band"] else None
    if tpl:
        band = os.path.join(tpl, "calibration.json") if case["band"] == "template" else crafted_band(rng, tpl, d)
        args = [a for a in args if not a.startswith(("--fit", "--holdout"))] + ["--holdout=0:1e9", "--band-from",
                                                                                  band]
        if rng.random() < 0.5:
            args[1] = os.path.join(tpl, rng.choice(["calibrated_a.toml", "calibrated_b.toml"]))
    return args


def expected(args, written):
    """The result set of a successful calibration over several traces."""
    base = {"calibration.json", "fit.csv", ".geartherm-output"}
    if any(a.startswith("--profile") for a in args):
        base.add("profile.csv")
    models = {w for w in written if w.startswith("calibrated")}
    one = models == {"calibrated.toml"}
    per_trace = models and all(w.startswith("calibrated_") and w.endswith(".toml") for w in models)
    single = {"cycle.csv", "calibration.png"}
    return (one or per_trace) and (written - models - single) == base


def run_case(case, ctx):
    res = core.new_result(case)
    with tempfile.TemporaryDirectory(prefix="hostile_") as d:
        args = build_args(case, ctx, d)
        res["cmd"] = " ".join(a.replace(d, "DIR") for a in args)[:600]
        outparent = os.path.join(d, "outs")
        os.mkdir(outparent)
        out = os.path.join(outparent, "o")
        if case["preload"]:
            shutil.copytree(ctx.templates["run"], out)
        before = core.snapshot(out)
        p = core.run([ctx.bin] + args + ["--out", out], cwd=d, timeout=ctx.limit * 3)
        core.classify(res, p, {0, 1, 2})
        if p.timed_out:
            return res
        beside = sorted(os.listdir(outparent))
        if p.rc != 0:
            if before:
                core.unchanged(res, before, out)
            elif beside:
                res["classes"].append("stray")
                res["detail"] = f"exit {p.rc} but wrote {beside}"
            if p.rc == 1 and not p.err.strip():
                res["classes"].append("bad_message")
                res["detail"] = "exit 1 without a message"
            return res
        written = set(os.listdir(out))
        if not expected(args, written):
            res["classes"].append("stray")
            res["detail"] = f"result set {sorted(written)}"
        core.check_files(res, out)
        if core.non_finite_in(p.out.decode(errors="replace").replace(d, "DIR")):
            res["classes"].append("non_finite")
            res["detail"] = "stdout"
    return res
