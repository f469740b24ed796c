"""Uncertainty studies and FMU export (families ``uq`` and ``fmu``).

``uq``: a small linear model (the PT6 spur pair with one capacity node between two boundaries,
as tests/uq_cli.rs builds it) with a generated ``[uncertainty]`` — distributions with hostile
parameters (negative widths, reversed bounds, far-tail truncations, log-normals on
temperatures, missing and extra parameters), key paths that do not exist or do not parse,
duplicates, correlations out of range or not positive definite, hostile sample counts, a
calibration block — or the same inputs in a study file; and hostile options (``--samples``,
``--limit``, ``--percentiles``, ``--sobol``, ``--series-points``, ``--bootstrap``,
``--confidence``, ``--shard``, a steady point). Half the cases write into a directory holding a
previous complete result of another study (a journal of other inputs: refused, left byte for
byte); some run twice (the second resumes and must give the same bands). ``check`` on the same
model must refuse exactly when ``uq`` refuses the model's own ``[uncertainty]``.

``fmu``: ``geartherm fmu`` with hostile ``--param`` key paths and ``--out`` names (no ``.fmu``,
a directory, a missing directory, an unwritable place): exit 0 writes exactly the FMU, any
failure writes nothing."""
import os
import random
import shutil
import tempfile

from . import core
from .cli import BAD_PATHS, HOSTILE

AMB = 'thermal.boundaries["ambient"].temp_c'
COOL = 'thermal.boundaries["coolant"].temp_c'
LINK = 'thermal.links["oil-air"].conductance_w_per_k'
GOOD_INPUTS = [
    (AMB, {"dist": "normal", "mean": 20.0, "sd": 2.0}),
    (COOL, {"dist": "uniform", "lo": 55.0, "hi": 65.0}),
    (LINK, {"dist": "triangular", "lo": 2.0, "mode": 3.0, "hi": 4.0}),
    (LINK, {"dist": "lognormal", "median": 1.0, "sigma_ln": 0.2, "relative": True}),
    ('thermal.nodes["oil"].capacity_j_per_k', {"dist": "lognormal", "median": 2000.0, "sigma_ln": 0.1}),
]
BAD_INPUT_PATHS = ['thermal.links["nope"].conductance_w_per_k', "thermal.links[\"oil-air\"].conductance",
                   "lubrication.nope", "gears[99].module_mm", "model.name"] + BAD_PATHS[:12]
PARAMS = {"normal": ["mean", "sd"], "lognormal": ["median", "sigma_ln"], "uniform": ["lo", "hi"],
          "triangular": ["lo", "mode", "hi"]}
EXPECTED_RUN = {"uq.json", "bands.csv", "bands.parquet", "study.csv", "study.parquet"}


def linear_model(root, uncertainty):
    pt6 = open(os.path.join(root, "models", "pt6_spur_pair.toml")).read()
    head = pt6[:pt6.index("\n[thermal]")]
    return (f'{head}\n[thermal]\noil_node = "oil"\ninitial_temp_c = 10.0\n\n[[thermal.nodes]]\nname = "oil"\n'
            'capacity_j_per_k = 2000.0\n\n[[thermal.boundaries]]\nname = "ambient"\ntemp_c = 20.0\n\n'
            '[[thermal.boundaries]]\nname = "coolant"\ntemp_c = 60.0\n\n[[thermal.links]]\nname = "oil-air"\n'
            'between = ["oil", "ambient"]\nconductance_w_per_k = 3.0\n\n[[thermal.links]]\nname = "oil-coolant"\n'
            f'between = ["oil", "coolant"]\nconductance_w_per_k = 1.0\n\n{uncertainty}')


def standstill(n=20):
    return "time_s,input_speed_rpm,input_torque_nm,gear\n" + "".join(f"{k * 50},0,0,1\n" for k in range(n + 1))


def q(path):
    return "'" + path + "'" if "'" not in path and "\n" not in path else '"' + path.replace('"', '\\"') + '"'


def hostile_number(rng, good):
    return rng.choice(HOSTILE) if rng.random() < 0.5 else repr(good * rng.choice([-1, 0, 1e-9, 1e9, 1]))


def gen_input(rng, bad, taken=()):
    """One `[[uncertainty.inputs]]` table and the key path it samples (a valid one on a key
    path not in `taken`, unless `bad`)."""
    path, d = rng.choice(GOOD_INPUTS if bad else [x for x in GOOD_INPUTS if x[0] not in taken])
    d = dict(d)
    if bad and rng.random() < 0.25:
        path = rng.choice(BAD_INPUT_PATHS)
    if bad and rng.random() < 0.5:
        key = rng.choice(PARAMS[d["dist"]])
        d[key] = hostile_number(rng, d[key]) if rng.random() < 0.7 else None
    if bad and rng.random() < 0.15:
        d[rng.choice(["sd", "mode", "median", "hi"])] = 1.0  # a parameter of another family
    if bad and rng.random() < 0.15:
        d["dist"] = rng.choice(["lognormal", "beta", "", "NORMAL"])
    if bad and rng.random() < 0.3:
        lo, hi = rng.choice([(-1e9, 1e9), (5.0, 1.0), (1e6, 2e6), (0.0, 0.0), (18.0, 22.0), (-50.0, 500.0)])
        d["truncate"] = f"[{lo!r}, {hi!r}]"
    lines = ["[[uncertainty.inputs]]", f"path = {q(path)}"]
    for k, v in d.items():
        if v is None:
            continue
        if isinstance(v, bool):
            v = "true" if v else "false"
        elif k == "dist":
            v = f'"{v}"'
        lines.append(f"{k} = {v}")
    return "\n".join(lines) + "\n", path


def gen_uncertainty(rng, bad):
    text, paths = "", []
    if rng.random() < 0.3:
        n = rng.choice(["0", "-1", "1000001", '"x"', "8", "16", "1e3"]) if bad else rng.choice(["8", "16"])
        text += f"[uncertainty]\nsamples = {n}\n"
    for _ in range(rng.choice([0, 1, 2, 2, 3]) if bad else rng.choice([1, 2, 3])):
        t, p = gen_input(rng, bad, paths)
        text += t
        paths.append(p)
    if bad and paths and rng.random() < 0.25:
        for _ in range(rng.choice([1, 2, 3])):
            a, b = rng.choice(paths), rng.choice(paths + [AMB, "nope"])
            r = rng.choice(["0.3", "-0.5", "0.99", "1", "-1", "2", "nan", "0.0"]) if bad else "0.3"
            text += f"[[uncertainty.correlations]]\nbetween = [{q(a)}, {q(b)}]\nrank = {r}\n"
    elif len(paths) > 1 and rng.random() < 0.25:
        text += f"[[uncertainty.correlations]]\nbetween = [{q(paths[0])}, {q(paths[1])}]\nrank = 0.3\n"
    if bad and rng.random() < 0.1:
        cov = rng.choice(["[[0.01]]", "[[-1.0]]", "[[nan]]", "[[0.01, 0.0]]", "[]"])
        text += (f"[uncertainty.calibration]\nparameters = [{q(LINK)}]\nscale = [\"{rng.choice(['log', 'linear', 'x'])}\"]\n"
                 f"value = [{rng.choice(['3.0', '-3.0', '0.0', 'nan'])}]\ncovariance = {cov}\n")
    return text


def gen_options(rng, bad):
    v = lambda good, hostile: rng.choice(hostile) if bad and rng.random() < 0.3 else rng.choice(good)
    args = ["--samples", v(["4", "8", "16"], ["0", "-1", "1000001", "x", "1e3", ""])] if rng.random() < 0.7 else []
    if rng.random() < 0.3:
        args += ["--limit", v(["oil=30", "oil=25.5"], ["nope=1", "oil=nan", "oil=x", "=", "oil", "oil=1e300", "oil=-300"])]
    if rng.random() < 0.2:
        args += ["--percentiles", v(["5,50,95", "10,90"], ["95,5", "0,100", "nan", "x", "", "50,50"])]
    if rng.random() < 0.15:
        # Saltelli's design runs N(d + 2) samples: a small N (the default 1000 would take
        # minutes on 2 cores, which is cost, not a fault).
        args += ["--sobol"] + ([] if "--samples" in args else ["--samples", "8"])
    if rng.random() < 0.15:
        args += ["--series-points", v(["11", "51"], ["0", "1", "-5", "1e9", "x"])]
    if rng.random() < 0.1:
        args += ["--bootstrap", v(["0", "50"], ["10001", "-1", "x"])]
    if rng.random() < 0.1:
        args += ["--confidence", v(["0.9", "0.95"], ["1", "0.5", "nan", "x", "0"])]
    if rng.random() < 0.1:
        args += ["--seed", v(["1", "7"], ["-1", "x", "18446744073709551616"])]
    if rng.random() < 0.1:
        args += ["--shard", v(["1/2", "2/2"], ["0/2", "3/2", "x", "1/0"])]
    return args


def make_uq_case(i, rng, root):
    bad = rng.random() < 0.5
    unc = gen_uncertainty(rng, bad)
    in_study = rng.random() < 0.2
    case = {"id": i, "family": "uq", "model_text": linear_model(root, "" if in_study else unc), "cmd": "uq"}
    if in_study:
        plan = rng.choice(["qmc", "qmc", "saltelli", "grid", "random"]) if bad else "qmc"
        case["study_text"] = (f'[study]\nname = "u"\nmodel = "m.toml"\n[job]\nkind = "run"\ncycles = ["CYCLE"]\n'
                              f'[sampling]\nplan = "{plan}"\ncases = {rng.choice(["8", "0", "16"])}\n{unc}')
    target = "STUDY" if in_study else "MODEL"
    job = (["--gear", "1", "--speed-rpm", rng.choice(["0", "500", "nan", "-1"] if bad else ["0", "500"]), "--torque-nm", "10"]
           if rng.random() < 0.15 else ["--cycle", "CYCLE"])
    case["args"] = ["uq", target] + job + gen_options(rng, bad) + ["--out", "OUT", "--quiet"]
    case["preload"] = rng.random() < 0.25
    case["resume"] = not case["preload"] and rng.random() < 0.2
    case["label"] = " ".join(case["args"]) + " | " + unc.replace("\n", " ")[:300]
    return case


def make_fmu_case(i, rng, root, texts):
    from .cli import leaf_paths
    m = rng.choice(["fzg_c.toml", "helical_stage.toml", "pt6_spur_pair.toml"])
    paths = [p for p, v in leaf_paths(texts.get(m) or open(os.path.join(root, "models", m)).read())]
    args = ["fmu", "MODEL", "--out", rng.choice(["OUT/x.fmu"] * 6 + ["OUT/x", "OUT", "NOWHERE/x.fmu",
                                                                      "/proc/x.fmu", "OUT/.fmu", "OUT/a b-ü.fmu"])]
    for _ in range(rng.choice([0, 1, 1, 2, 3])):
        r = rng.random()
        p = rng.choice(BAD_PATHS) if r < 0.3 else rng.choice(paths) + (rng.choice([".x", "[0]", ""]) if r < 0.4 else "")
        args += ["--param", p]
    return {"id": i, "family": "fmu", "model": m, "cmd": "fmu", "args": args, "label": " ".join(args)}


def make_case(i, rng, root, texts, family):
    return make_uq_case(i, rng, root) if family == "uq" else make_fmu_case(i, rng, root, texts)


# ---------------------------------------------------------------------------------------------

def run_case(case, ctx):
    return run_uq(case, ctx) if case["family"] == "uq" else run_fmu(case, ctx)


def previous(ctx, d):
    """A complete result of another uq study (its own inputs) in `d/prev`."""
    prev = os.path.join(d, "prev")
    model = os.path.join(d, "prev.toml")
    with open(model, "w") as f:
        f.write(linear_model(ctx.root, gen_input(random.Random(1), False)[0]))
    p = core.run([ctx.bin, "uq", model, "--cycle", os.path.join(d, "c.csv"), "--samples", "4", "--out", prev,
                  "--quiet"], cwd=d, timeout=ctx.limit * 3)
    if p.rc != 0:
        raise RuntimeError(f"previous uq failed: {p.err.decode(errors='replace')[-300:]}")
    os.remove(model)
    return prev


def run_uq(case, ctx):
    res = core.new_result(case)
    with tempfile.TemporaryDirectory(prefix="hostile_uq_") as d:
        with open(os.path.join(d, "m.toml"), "w") as f:
            f.write(case["model_text"])
        with open(os.path.join(d, "c.csv"), "w") as f:
            f.write(standstill())
        if "study_text" in case:
            with open(os.path.join(d, "s.toml"), "w") as f:
                f.write(case["study_text"].replace("CYCLE", os.path.join(d, "c.csv")))
        outparent = os.path.join(d, "outs")
        os.mkdir(outparent)
        out = os.path.join(outparent, "o")
        if case["preload"]:
            shutil.move(previous(ctx, d), out)
        before = core.snapshot(out)
        subs = {"MODEL": os.path.join(d, "m.toml"), "STUDY": os.path.join(d, "s.toml"), "OUT": out,
                "CYCLE": os.path.join(d, "c.csv")}
        args = [subs.get(a, a) for a in case["args"]]
        p = core.run([ctx.bin] + args, cwd=d, timeout=ctx.limit * 3)
        core.classify(res, p, {0, 1, 2, 3})
        if p.timed_out:
            return res
        check_uq(res, case, p, out, outparent, before)
        if "study_text" not in case and p.rc in (0, 1):
            check_agrees(res, ctx, d, p, args)
        if case["resume"] and p.rc == 0 and not res["classes"]:
            again(res, ctx, d, args, out)
        core.stray_in(res, d, {"m.toml", "c.csv", "s.toml", "outs"})
    return res


def check_uq(res, case, p, out, outparent, before):
    beside = sorted(os.listdir(outparent))
    if p.rc != 0:
        if before:
            core.unchanged(res, before, out)
        elif beside:
            res["classes"].append("stray")
            res["detail"] = f"exit {p.rc} but wrote {beside}"
        return
    if beside != ["o"]:
        res["classes"].append("stray")
        res["detail"] = f"beside the target: {beside}"
        return
    written = set(os.listdir(out))
    want = EXPECTED_RUN if "--gear" not in case["args"] else EXPECTED_RUN - {"bands.csv", "bands.parquet"}
    if "--shard" in case["args"]:
        # A shard journals its samples only (a later run without --shard merges the journals).
        want = {n for n in written if n.startswith("journal.shard-")} or {"journal.shard-I-of-N.jsonl"}
    if not want <= written:
        res["classes"].append("stray")
        res["detail"] = f"result set {sorted(written)}: missing {sorted(want - written)}"
    core.check_files(res, out)


def check_agrees(res, ctx, d, p, args):
    """`check` on the model passes when `uq` ran on it, and refuses when `uq` refused a problem
    of the model's own `[uncertainty]`."""
    err = p.err.decode(errors="replace")
    if p.rc == 1 and not model_problem(err):
        return
    c = core.run([ctx.bin, "check", os.path.join(d, "m.toml")], cwd=d)
    if c.rc != (0 if p.rc == 0 else 1):
        res["classes"].append("wrong_exit")
        res["detail"] = f"uq exit {p.rc}, check exit {c.rc}: {err[-300:]} | {c.err.decode(errors='replace')[-200:]}"


def model_problem(err):
    """A refusal of the `[uncertainty]` itself (not one of the options on the command line)."""
    return any(k in err for k in ("uncertainty.inputs[", "uncertainty.correlations", "uncertainty.samples",
                                  "uncertainty.calibration"))


def again(res, ctx, d, args, out):
    """The same command again: it resumes from the journal (nothing to solve) and writes the
    same bands (a shard: the same journal)."""
    name = "bands.csv" if "--gear" not in args and "--shard" not in args else None

    def read():
        if name is None or not os.path.exists(os.path.join(out, name)):
            return None
        with open(os.path.join(out, name), "rb") as f:
            return f.read()

    first = read()
    p = core.run([ctx.bin] + args, cwd=d, timeout=ctx.limit * 3)
    core.classify(res, p, {0})
    if name is not None and read() != first:
        res["classes"].append("changed_on_failure")
        res["detail"] = "resumed bands.csv differs from the first run's"


def run_fmu(case, ctx):
    res = core.new_result(case)
    with tempfile.TemporaryDirectory(prefix="hostile_fmu_") as d:
        model = os.path.join(d, "m.toml")
        shutil.copy(os.path.join(ctx.root, "models", case["model"]), model)
        out = os.path.join(d, "outs")
        os.mkdir(out)
        args = [a.replace("OUT", out).replace("NOWHERE", os.path.join(d, "nowhere")) if a.startswith(("OUT", "NOWHERE"))
                else (model if a == "MODEL" else a) for a in case["args"]]
        p = core.run([ctx.bin] + args, cwd=d, timeout=ctx.limit * 3)
        core.classify(res, p, {0, 1, 3})
        written = sorted(os.listdir(out))
        target = args[args.index("--out") + 1]
        if p.rc == 0 and written != [os.path.basename(target)]:
            res["classes"].append("stray")
            res["detail"] = f"exit 0: wrote {written}"
        elif p.rc not in (0, None) and written:
            res["classes"].append("stray")
            res["detail"] = f"exit {p.rc} but wrote {written}"
        core.stray_in(res, d, {"m.toml", "outs"})
    return res
