"""`calibrate` over several traces (family ``calibrate_traces``): two or three generated rig
traces of the helical stage (one to three segments each, cut by gaps in time), shared and
per-trace `--fit` keys (`KEY@N`, `KEY@name`, `KEY@*`), priors on the command line and in a
priors file, `--profile`, `--residuals`, `--rated`, `--gearbox-kind`, `--holdout`, `--band-from`
a calibration over several traces (made once per campaign), and `--segment` over one trace of
several segments. About two cases in five are valid calibrations that must run to a result
(exit 0); each of the others carries one to three hostile mutations (bad cells, times or
columns; unknown, doubled or unboundable keys and traces; priors of negative, zero or
non-finite width; options beyond their limits; a crafted `--band-from`). Half of the cases write
into a directory that holds a complete previous result set, which a failure must leave byte for
byte; every written `calibrated*.toml` must pass `check`."""
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
# Share of the cases that are valid calibrations (no mutation).
VALID = 0.4
# The hostile mutations: what each changes is made by `mutate_*` below (traces) or by the
# argument builders (options), each given the set of mutations of its case.
MUTATIONS = ["cells", "times", "columns", "same_trace", "fit", "prior", "priors_file", "option",
             "segment", "band"]


def gen_trace(rng, mass, segments, n, hostile=()):
    """A warm-up of the helical stage measured on oil and housing, `segments` segments a day
    apart of `n` rows each; `hostile` ⊆ {"cells", "times", "columns"} spoils it."""
    cols = list(COLUMNS)
    if "columns" in hostile:
        r = rng.random()
        if r < 0.35:
            cols.remove(rng.choice(cols[4:]))
        elif r < 0.7:
            cols[rng.randrange(4, len(cols))] = rng.choice(["node:bearing_x", "boundary:sun", "node:oil"])
        else:
            cols.append(rng.choice(["node:bearing_x", "node:housing", "time_s"]))
    elif rng.random() < 0.2:
        head, tail = cols[:4], cols[4:]
        rng.shuffle(tail)
        cols = head + tail
    rows, t = [",".join(cols)], 0.0
    bad_cells = rng.choice([0.01, 0.05, 0.3]) if "cells" in hostile else 0.0
    bad_times = [0.0, -60.0, 1e-9, 1e12] if "times" in hostile else []
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
            t += rng.choice([60.0] * 8 + bad_times)
        t += 90_000.0
    return "\n".join(rows) + "\n"


def fit_args(rng, names, bad):
    """One to three valid `--fit` keys (distinct parameters); with `bad` one hostile key more."""
    mass = rng.choice([f"{M}@*=2:60", f"{M}@0=2:60", f"{M}@{names[-1]}=2:60", f"{M}=2:60"])
    h = [H, f"{H}=50:5000"] + ([f"{H}@*=50:5000"] if len(names) > 1 else [])
    out = [rng.choice(h)] + ([mass] if rng.random() < 0.7 else [])
    if bad:
        out.append(rng.choice([f"{M}@9", f"{M}@nobody", "thermal.nodes[9].mass_kg", 'thermal.nodes["oil"].mass_kg@*',
                               f"{H}@*=1e-9:1e9", "losses.stavytskyi_ks=0.2:0.9", f"{H}=5000:50", f"{M}@*=-2:60",
                               f"thermal.nodes[1].mass_kg@{names[0]}", f"{H}=nan:1", "losses.multiplier.churning=0.1:10"]))
    return [f"--fit={k}" for k in dict.fromkeys(out)]


def fitted_keys(fits):
    """The key (with its @TRACE) of each `--fit=` argument."""
    return [f.split("=", 1)[1].split("=")[0] for f in fits]


def prior_args(rng, fits, d, bad, bad_file):
    """Priors on fitted keys (command line, or a priors file); `bad`/`bad_file` spoil one."""
    keys = fitted_keys(fits)
    out = []
    if rng.random() < 0.4 or bad:
        k = rng.choice(keys)
        dist = rng.choice(["normal:500:200", "lognormal:500:0.5"] if k.startswith(H) else ["normal:20:10", "lognormal:20:0.5"])
        if bad:
            k = rng.choice([k, f"{M}@nobody", f"{M}@7", "losses.multiplier.churning", k + "@a" if "@" not in k else k])
            dist = rng.choice([dist.rsplit(":", 1)[0] + ":" + w for w in ["0", "-1", "nan", "inf", "1e-300", "x"]]
                              + ["cauchy:20:1", "lognormal:-1:0.5", "normal:20"])
        out.append(f"--prior={k}={dist}")
    free = [k for k in keys if not any(a.startswith(f"--prior={k}=") for a in out)]
    if (rng.random() < 0.3 and free) or bad_file:
        path = os.path.join(d, "priors.toml")
        k = rng.choice(free or keys)
        mean, sd = ("500", "200") if k.startswith(H) else ("20", "10")
        sd = rng.choice(["-1", "0", "nan", '"x"', "inf"]) if bad_file else sd
        extra = rng.choice(["", "bogus = 1\n", "[[prior]]\n"]) if bad_file else ""
        with open(path, "w") as f:
            f.write(f"[[prior]]\nkey = '{k}'\ndistribution = 'normal'\nmean = {mean}\nsd = {sd}\n{extra}")
        out += ["--priors", path]
    return out


def option_args(rng, names, fits, bad):
    """Valid options with their own chances; with `bad` one of them beyond its limits."""
    a = []
    keys = fitted_keys(fits)
    if rng.random() < 0.4:
        a += ["--residuals", rng.choice(["ar1", "ar1-gls", "independent"])]
    if rng.random() < 0.25:
        a += [f"--profile={rng.choice(keys)}"]
    if rng.random() < 0.3:
        a += [f"--rated={rng.choice(['4000:250', '3000:200'])}"]
    if rng.random() < 0.25:
        a += ["--gearbox-kind", "wind-turbine"]
    if rng.random() < 0.3:
        a += [f"--holdout={rng.choice(['0:300', '600:1100'])}"]
    if rng.random() < 0.2:
        a += ["--max-iterations", rng.choice(["1", "3", "10"])]
    if rng.random() < 0.25:
        a += ["--band-quantile", rng.choice(["empirical", "t"])]
    if bad:
        a += rng.choice([["--residuals", rng.choice(["ar2", "AR1", ""])], ["--profile=x.y"], [f"--profile={M}@nobody"],
                         [f"--rated={rng.choice(['0:1', '1e9:1', '-5:2', 'x', '3000:-100', 'nan:1'])}"],
                         ["--gearbox-kind", rng.choice(["ship", ""])],
                         [f"--holdout={rng.choice(['0:1e9', '600:300', 'nan:1', '0:0', 'inf:1'])}"],
                         ["--max-iterations", rng.choice(["0", "1001", "-1", "1e3"])],
                         ["--band-quantile", rng.choice(["normal", "T", ""])],
                         ["--rtol", rng.choice(["0", "1", "nan"])], ["--atol", rng.choice(["0", "2", "-1"])]])
    return a


def make_case(i, rng):
    """A valid several-trace calibration (share VALID) or one with one to three mutations."""
    muts = set() if rng.random() < VALID else set(rng.sample(MUTATIONS, rng.choice([1, 1, 2, 3])))
    band = "band" in muts or rng.random() < 0.1
    single = "segment" not in muts and not band and rng.random() < 0.15
    # The band's calibration (the template) fitted traces a and b.
    n = 1 if single else 2 if band else rng.choice([2, 2, 3])
    names = ["a", "b", "c"][:n]
    segs = [rng.choice([2, 3]) if single else rng.choice([1, 2, 2]) for _ in names]
    spoil = muts & {"cells", "times", "columns"}
    spoilt = rng.randrange(n)
    traces = {name: gen_trace(rng, rng.choice([8.0, 11.0, 20.0]), segs[j], rng.choice([12, 16, 20]),
                              spoil if j == spoilt else ())
              for j, name in enumerate(names)}
    return {"id": i, "family": "calibrate_traces", "traces": traces, "names": names, "mutations": sorted(muts),
            "seed": rng.randrange(2 ** 62), "preload": rng.random() < 0.5, "single": single,
            "band": ("crafted" if "band" in muts else "template") if band else None}


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
        with open(p, "w") as f:
            f.write(gen_trace(rng, mass, 2, 20))
        paths.append(p)
    out = os.path.join(d, "cal")
    args = [ctx.bin, "calibrate", os.path.join(ctx.root, "models", MODEL), "--trace", paths[0], "--trace",
            paths[1], f"--fit={H}", f"--fit={M}@*=2:60", "--out", out]
    p = subprocess.run(args, capture_output=True)
    if p.returncode != 0:
        print(f"calibrate template failed: {p.stderr.decode(errors='replace')[-300:]}", file=sys.stderr)
        return None
    return out


def crafted_band(rng, tpl, d):
    with open(os.path.join(tpl, "calibration.json")) as f:
        doc = json.load(f)
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


def write_traces(case, d):
    paths = []
    for name in case["names"]:
        p = os.path.join(d, f"{name}.csv")
        with open(p, "w") as f:
            f.write(case["traces"][name])
        paths.append(p)
    return paths


def build_args(case, ctx, d):
    import random
    rng = random.Random(case["seed"])
    muts = set(case.get("mutations", []))
    paths = write_traces(case, d)
    if "same_trace" in muts:
        paths.append(paths[0])
    args = ["calibrate", os.path.join(ctx.root, "models", MODEL)]
    for p in paths:
        args += ["--trace", p]
    names = case["names"] if not case["single"] else ["a"]
    fits = fit_args(rng, names, "fit" in muts)
    if case["single"]:
        fits = [f.split("@")[0] + ("=" + f.split("=", 2)[2] if f.count("=") == 2 else "") if "@" in f else f
                for f in fits]
        fits = list(dict.fromkeys(fits))
    args += fits + prior_args(rng, fits, d, "prior" in muts, "priors_file" in muts)
    args += option_args(rng, names, fits, "option" in muts)
    if case["single"]:
        args += ["--segment", rng.choice(["all", "0,1"])]
    elif "segment" in muts:
        args += ["--segment", rng.choice(["all", "0,1", "0", "5", ",", "1,1"])]
    tpl = template(ctx) if case["band"] else None
    if tpl:
        band = os.path.join(tpl, "calibration.json") if case["band"] == "template" else crafted_band(rng, tpl, d)
        args = [a for j, a in enumerate(args) if not (a == "--priors" or (j and args[j - 1] == "--priors"))]
        args = [a for a in args if not a.startswith(("--fit", "--holdout", "--prior", "--profile"))]
        args += ["--holdout=0:1e9", "--band-from", band]
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


def rig_cycle(case, d):
    """The rig cycle (time, speed, torque, gear) of the case's first trace, or None when its
    first columns are not those."""
    lines = case["traces"][case["names"][0]].strip().split("\n")
    if not lines[0].startswith(",".join(COLUMNS[:4]) + ","):
        return None
    path = os.path.join(d, "cycle_of_a.csv")
    with open(path, "w") as f:
        f.write("\n".join(",".join(line.split(",")[:4]) for line in lines) + "\n")
    return path


def check_written(res, ctx, case, out, d):
    """Every written calibrated model passes `check` and `run` takes it (on the first trace's
    rig cycle): an accepted calibration writes models that later commands accept."""
    cycle = rig_cycle(case, d)
    for name in sorted(os.listdir(out)):
        if not (name.startswith("calibrated") and name.endswith(".toml")):
            continue
        model = os.path.join(out, name)
        runs = [["check", model]]
        if cycle:
            runs.append(["run", model, "--cycle", cycle, "--quiet", "--summary-only", "--out", os.path.join(d, "r")])
        for args in runs:
            p = core.run([ctx.bin] + args, cwd=d, timeout=ctx.limit)
            if p.timed_out or p.rc not in (0, 2):
                res["classes"].append("later_refused")
                res["detail"] = f"{args[0]} {name}: exit {p.rc}: {p.err.decode(errors='replace')[-300:]}"


def names_input(err, args):
    """A refusal's message names something the user gave: a file, a key path, a value or an
    option."""
    words = set()
    for a in args[1:]:
        for part in a.split("=", 1) if a.startswith("--") else [a]:
            words |= {part, part.lstrip("-"), part.lstrip("-").replace("-", "_"), os.path.basename(part)}
            words |= set(part.split("@")) | set(part.split(":"))
    words |= {"trace", "fit", "prior", "segment", "band", "calibration.json"}
    return any(w and len(w) > 1 and w in err for w in words - {"calibrate"})


def refusal(res, p, args, before, out, outparent):
    """A refused case: nothing written, the previous result set unchanged, a message."""
    beside = sorted(os.listdir(outparent))
    if before:
        core.unchanged(res, before, out)
    elif beside:
        res["classes"].append("stray")
        res["detail"] = f"exit {p.rc} but wrote {beside}"
    err = p.err.decode(errors="replace").strip()
    if p.rc == 1 and not names_input(err, args):
        res["classes"].append("bad_message")
        res["detail"] = f"exit 1 with message {err!r}"


def run_case(case, ctx):
    res = core.new_result(case)
    with tempfile.TemporaryDirectory(prefix="hostile_") as d:
        args = build_args(case, ctx, d)
        res["cmd"] = f"[{','.join(case.get('mutations', [])) or 'valid'}] " + \
            " ".join(a.replace(d, "DIR") for a in args)[:600]
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
        if p.rc != 0:
            refusal(res, p, args, before, out, outparent)
            if not case.get("mutations"):
                res["classes"].append("valid_refused")
                res["detail"] = f"valid case exit {p.rc}: {p.err.decode(errors='replace')[-300:]}"
            return res
        res["fit"] = any(a.startswith("--fit") for a in args)
        res["valid"] = not case.get("mutations")
        written = set(os.listdir(out))
        if not expected(args, written):
            res["classes"].append("stray")
            res["detail"] = f"result set {sorted(written)}"
        core.check_files(res, out)
        check_written(res, ctx, case, out, d)
        if core.non_finite_in(p.out.decode(errors="replace").replace(d, "DIR")):
            res["classes"].append("non_finite")
            res["detail"] = "stdout"
    return res
