"""Study files (family ``study``): generated plans, parameters, jobs, outputs and names
(``study_spec``); a study SIGKILLed at a random moment and resumed (``study_kill``); two writers
into one directory at once, the same study or two shards (``study_two``); grids and samples at
and beyond the plan's limits (``study_huge``). A completed study's table must hold every case
of its `--list` exactly once."""
import csv
import io
import math
import os
import random
import shutil
import signal
import subprocess
import tempfile
import time

from . import core
from .cli import HOSTILE, leaf_paths

MODEL = "fzg_c.toml"
NUMERIC = None  # numeric leaf paths of the study model, filled on first use


def toml(v):
    """A Python value as TOML value text (floats may be nan/inf, as TOML allows)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml(str(k))} = {toml(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml(x) for x in v) + "]"
    return str(v)


def render(spec):
    """Study text from {section: {key: value}} and a list of parameter tables."""
    lines = []
    for sec in ("study", "job", "sampling", "outputs"):
        if sec in spec:
            lines.append(f"[{sec}]")
            lines += [f"{toml(k)} = {toml(v)}" for k, v in spec[sec].items()]
    for p in spec.get("parameters", []):
        lines.append("[[parameters]]")
        lines += [f"{toml(k)} = {toml(v)}" for k, v in p.items()]
    return "\n".join(lines) + "\n"


def numeric_paths(root):
    global NUMERIC
    if NUMERIC is None:
        text = open(os.path.join(root, "models", MODEL)).read()
        NUMERIC = [(p, v) for p, v in leaf_paths(text)
                   if isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0]
    return NUMERIC


def hostile_number(rng):
    return rng.choice([0.0, -1.0, 1e308, -1e308, 1e-308, float("nan"), float("inf"), 3.5, 1e30, -0.0])


def gen_job(rng, small):
    k = rng.random()
    if k < 0.45:
        pts = [{"gear": "1", "speed_rpm": rng.choice([500.0, 1450.0, 3000.0]), "torque_nm": rng.choice([10.0, 100.0])}
               for _ in range(rng.randint(1, 2))]
        if not small and rng.random() < 0.2:
            pts[0][rng.choice(["speed_rpm", "torque_nm", "gear", "ambient_c", "vehicle_speed_kmh", "nope"])] = \
                rng.choice([hostile_number(rng), "x", "9", -1.0])
        return {"kind": "steady", "points": pts}
    if k < 0.8:
        job = {"kind": "run", "cycles": [rng.choice(["RIG", "RIG", "wltc"])]}
        if not small and rng.random() < 0.3:
            job["cycles"] = rng.choice([[], ["nope"], ["RIG", "RIG"], ["DIR"], ["/dev/null"]])
        if rng.random() < 0.5:
            opts = {"summary_only": rng.random() < 0.7}
            if not small and rng.random() < 0.4:
                opts[rng.choice(["rtol", "atol", "initial_temp_c", "frozen_viscosity_c", "max_steps", "solver", "x"])] = \
                    rng.choice([hostile_number(rng), "bdf", "x", 10, -60.0, 199.0])
            job["options"] = opts
        return job
    job = {"kind": "map", "gear": "1", "speed_rpm": [1000.0, 2000.0], "torque_nm": [10.0, 50.0]}
    if not small and rng.random() < 0.3:
        job[rng.choice(["speed_rpm", "torque_nm", "gear"])] = rng.choice([[], [hostile_number(rng)], "x", [1.0] * 3000])
    return job


def gen_parameter(rng, root, small):
    path, val = rng.choice(numeric_paths(root))
    r = rng.random()
    if r < 0.4:
        p = {"path": path, "range": [val * 0.8, val * 1.2]}
    elif r < 0.6:
        p = {"path": path, "scale": [0.5, 1.5]}
    elif r < 0.8:
        p = {"path": path, "values": [val * 0.9, val, val * 1.1][: rng.randint(1, 3)]}
    else:
        p = {"path": "oil.catalogue", "values": rng.choice([["fva_3a", "w326"], ["fva_3a"], ["nope"]])}
    if rng.random() < 0.3 and "values" not in p:
        p["levels"] = rng.choice([1, 2, 3])
    if small:
        return p
    r = rng.random()
    if r < 0.1:
        p["path"] = rng.choice(["", "nope.x", "gears[99]", "gears[0]", "oil", "model.name", "a" * 3000, "x\ny"])
    elif r < 0.2:
        key = rng.choice(["range", "scale", "values", "levels"])
        p[key] = rng.choice([[hostile_number(rng), 1.0], [2.0, 1.0], [], "x", hostile_number(rng), 0, -3,
                             [1.0, 2.0, 3.0], [[1.0]], {"a": 1}])
    elif r < 0.25:
        p.update({"range": [1.0, 2.0], "values": [1.0]})
    return p


def gen_spec(rng, root, small):
    n = rng.randint(1, 3)
    spec = {"study": {"name": "s", "model": "MODEL"}, "job": gen_job(rng, small),
            "parameters": [gen_parameter(rng, root, small) for _ in range(n)]}
    if small:
        # A study that must run (kill and resume, two writers): each key path once.
        seen = set()
        spec["parameters"] = [p for p in spec["parameters"] if not (p["path"] in seen or seen.add(p["path"]))]
    plan = rng.choice(["grid", "grid", "lhs", "list"])
    spec["sampling"] = {"plan": plan}
    if plan == "lhs":
        spec["sampling"]["cases"] = rng.randint(1, 6)
        spec["sampling"]["seed"] = rng.randint(0, 2 ** 63)
    if plan == "list":
        for p in spec["parameters"]:
            p.pop("range", None), p.pop("scale", None), p.pop("levels", None)
            v = p.get("values") or [1.0, 2.0]
            p["values"] = (v * 2)[:2] if isinstance(v, list) else v
    if rng.random() < 0.3:
        spec["outputs"] = {"per_case": rng.random() < 0.5}
    if small:
        return spec
    mutate_spec(rng, spec)
    return spec


def mutate_spec(rng, spec):
    r = rng.random()
    if r < 0.1:
        spec["study"]["name"] = rng.choice(["", "../escape", "a/b", ".", "..", "x" * 300, "a\nb", "/abs", "ü", "-x"])
    elif r < 0.2:
        spec["study"]["model"] = rng.choice(["", "nope.toml", ".", "/dev/null", "/dev/zero", "MODEL_DIR", "s.toml"])
    elif r < 0.3:
        spec["sampling"][rng.choice(["plan", "cases", "seed", "x"])] = rng.choice(
            ["nope", 0, -1, 1e308, 2 ** 70, "3", 10 ** 7 + 1, float("nan")])
    elif r < 0.4:
        spec["outputs"] = {rng.choice(["pareto", "effects", "per_case", "x"]): rng.choice(
            [["nope", "x"], ["energy_total_j"], [], "x", True, ["energy_total_j", "cycle_efficiency"], 1])}
    elif r < 0.45:
        spec["parameters"] = []
    elif r < 0.5:
        spec["parameters"] = spec["parameters"] * 2


def study_text(rng, case, spec):
    text = render(spec)
    if case["garble"]:
        lines = text.split("\n")
        k = rng.randrange(len(lines))
        lines[k] = rng.choice(["", "[study", "x = ", lines[k] + lines[k], "[[parameters]]", "\x00", "name = 1"])
        text = "\n".join(lines)
    return text


def make_case(i, rng, root, sub):
    small = sub != "study_spec"
    case = {"id": i, "family": sub, "garble": sub == "study_spec" and rng.random() < 0.15}
    if sub == "study_huge":
        spec = huge_spec(rng, root)
    else:
        spec = gen_spec(rng, root, small)
    case["text"] = study_text(rng, case, spec)
    case["mode"] = rng.choice(["out", "out", "out", "list", "shard", "default"]) if sub == "study_spec" else "out"
    case["preload"] = sub == "study_spec" and rng.random() < 0.2
    case["delay_ms"] = rng.choice([0, 5, 20, 60, 150, 400])
    case["two"] = rng.choice(["same", "shards"])
    case["label"] = f"{sub} mode={case['mode']} " + case["text"].replace("\n", " ")[:300]
    return case


def huge_spec(rng, root):
    n = rng.choice([2, 3, 8, 20, 64])
    levels = rng.choice([10, 100, 3163, 10 ** 6, 10 ** 7, 10 ** 7 + 1, 2 ** 40])
    params = [{"path": "lubrication.oil_level_mm", "range": [30.0, 50.0], "levels": levels}]
    # Each key path once (a study refuses a path varied twice): real numeric leaves of the model,
    # scaled around their values.
    others = [p for p, _ in numeric_paths(root) if p != "lubrication.oil_level_mm"]
    params += [{"path": p, "scale": [0.9, 1.1], "levels": rng.choice([2, 10, 1000])}
               for p in rng.sample(others, min(n - 1, len(others)))]
    samp = {"plan": "grid"} if rng.random() < 0.7 else {"plan": "lhs", "cases": rng.choice([10 ** 7, 10 ** 7 + 1, 2 ** 63])}
    return {"study": {"name": "huge", "model": "MODEL"}, "sampling": samp,
            "job": {"kind": "steady", "points": [{"gear": "1", "speed_rpm": 1000.0, "torque_nm": 10.0}]},
            "parameters": params}


# ---------------------------------------------------------------------------------------------
# Running

class Scratch:
    def __init__(self, ctx, case):
        self.dir = tempfile.mkdtemp(prefix="hostile_study_")
        # The study runs two levels down, so that a name or path climbing out of the working
        # directory (`../x`) still lands inside the scratch directory, where it is seen.
        self.cwd = os.path.join(self.dir, "w", "v")
        os.makedirs(self.cwd)
        self.outs = os.path.join(self.cwd, "outs")
        os.mkdir(self.outs)
        self.out = os.path.join(self.outs, "o")
        self.study = os.path.join(self.cwd, "s.toml")
        subs = {'"MODEL"': f'"{os.path.join(ctx.root, "models", MODEL)}"', '"RIG"': f'"{ctx.rig}"',
                '"DIR"': f'"{self.dir}"', '"MODEL_DIR"': f'"{os.path.join(ctx.root, "models")}"'}
        text = case["text"]
        for k, v in subs.items():
            text = text.replace(k, v)
        with open(self.study, "w") as f:
            f.write(text)

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def study_args(self, ctx, *extra):
        return [ctx.bin, "study", self.study, "--quiet"] + list(extra)


def listed(ctx, sc):
    """Case ids of the study's `--list`, or None when the study is refused."""
    p = core.run(sc.study_args(ctx, "--list"), cwd=sc.cwd, timeout=ctx.limit * 3)
    if p.timed_out or p.rc != 0:
        return None
    return [l.split("\t", 1)[0] for l in p.out.decode(errors="replace").splitlines() if l]


def table_ids(res, out):
    path = os.path.join(out, "study.csv")
    if not os.path.isfile(path):
        res["classes"].append("stray")
        res["detail"] = "no study.csv after a study exited 0"
        return None
    with open(path, errors="replace") as f:
        rows = list(csv.DictReader(f))
    return [r.get("case") for r in rows]


def every_case_once(res, ids, expected):
    if ids is None or expected is None:
        return
    if sorted(ids) != sorted(expected) or len(set(ids)) != len(ids):
        res["classes"].append("stray")
        res["detail"] = f"study.csv holds {len(ids)} rows ({len(set(ids))} distinct), --list {len(expected)}"


def run_spec(case, ctx, sc, res):
    mode = case["mode"]
    extra = {"out": ["--out", sc.out], "list": ["--list"], "shard": ["--shard", "0/2", "--out", sc.out],
             "default": []}[mode]
    if case["preload"]:
        shutil.copytree(ctx.templates["study"], sc.out)
    before = core.snapshot(sc.out)
    p = core.run(sc.study_args(ctx, *extra), cwd=sc.cwd, timeout=ctx.limit * 3)
    core.classify(res, p, {0, 1, 2, 3})
    if p.timed_out:
        return
    stdout = p.out.decode(errors="replace").replace(sc.dir, "DIR")
    if p.rc == 0 and mode != "list" and core.non_finite_in(stdout):
        res["classes"].append("non_finite")
        res["detail"] = "stdout"
    if p.rc != 0:
        if before:
            core.unchanged(res, before, sc.out)
        return
    if mode == "out":
        every_case_once(res, table_ids(res, sc.out), listed(ctx, sc))
        core.check_files(res, sc.out)


def run_kill(case, ctx, sc, res):
    """Kill the study after `delay_ms`, resume it, and check the table."""
    args = sc.study_args(ctx, "--out", sc.out)
    p = subprocess.Popen(core.limited(args), cwd=sc.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         start_new_session=True)
    time.sleep(case["delay_ms"] / 1000)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    q = core.run(args, cwd=sc.cwd, timeout=ctx.limit * 3)
    core.classify(res, q, {0})
    if q.rc == 0:
        every_case_once(res, table_ids(res, sc.out), listed(ctx, sc))
        core.check_files(res, sc.out)


def run_two(case, ctx, sc, res):
    """Two writers at once: the same study (one may be refused, exit 3), or two shards (both
    succeed); then a plain run merges; every case exactly once."""
    if case["two"] == "same":
        a = b = sc.study_args(ctx, "--out", sc.out)
        allowed = {0, 3}
    else:
        a = sc.study_args(ctx, "--out", sc.out, "--shard", "0/2")
        b = sc.study_args(ctx, "--out", sc.out, "--shard", "1/2")
        allowed = {0}
    ps = [subprocess.Popen(core.limited(x), cwd=sc.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           start_new_session=True) for x in (a, b)]
    for p in ps:
        try:
            err = p.communicate(timeout=ctx.limit * 3)[1]
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            res["classes"].append("hang")
            return
        core.classify(res, core.Proc(p.returncode, b"", err, False), allowed)
        if p.returncode == 3 and b"another geartherm" not in err:
            res["classes"].append("wrong_exit")
            res["detail"] = f"exit 3 without naming the other writer: {err[-200:]}"
    q = core.run(sc.study_args(ctx, "--out", sc.out), cwd=sc.cwd, timeout=ctx.limit * 3)
    core.classify(res, q, {0})
    if q.rc == 0:
        every_case_once(res, table_ids(res, sc.out), listed(ctx, sc))


def run_huge(case, ctx, sc, res):
    """Beyond the plan's limit: refused within the time limit; within it: `--list` into a
    closed pipe ends quietly (141) or lists (0)."""
    r, w = os.pipe()
    os.close(r)
    p = core.run(sc.study_args(ctx, "--list"), cwd=sc.cwd, timeout=ctx.limit, stdout=w)
    os.close(w)
    core.classify(res, p, {1, 141})


def run_case(case, ctx):
    res = core.new_result(case)
    sc = Scratch(ctx, case)
    try:
        {"study_spec": run_spec, "study_kill": run_kill, "study_two": run_two,
         "study_huge": run_huge}[case["family"]](case, ctx, sc, res)
        beside = sorted(os.listdir(sc.outs))
        if beside not in ([], ["o"]):
            res["classes"].append("stray")
            res["detail"] = f"beside the study directory: {beside}"
        core.stray_in(res, sc.cwd, {"s.toml", "outs", "studies"})
        core.stray_in(res, os.path.join(sc.dir, "w"), {"v"})
        core.stray_in(res, sc.dir, {"w"})
    finally:
        sc.close()
    return res
