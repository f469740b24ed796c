"""Families on the model-reading commands (`check`, `info`, `losses`, `steady`, `map`, `run`,
`bench`): mutated and extreme model files, generated cycles, malformed and extreme options
(family ``cli``), and `--set` key paths and values on every one of them (family ``set``). Half
of the `run`, `map` and `bench` cases write into a directory that already holds a complete
previous result set, which a failure must leave byte for byte."""
import os
import random
import re
import shutil
import tempfile
import tomllib

from . import core

MODELS = ["fzg_c.toml", "at6_lepelletier.toml", "helical_stage.toml", "pt6_spur_pair.toml"]
GEAR = {"fzg_c.toml": "1", "at6_lepelletier.toml": "3", "helical_stage.toml": "1", "pt6_spur_pair.toml": "1"}
HOSTILE = ["0", "-0.0", "-1", "1e308", "-1e308", "1e-308", "1e-300", "1e100", "nan", "inf", "-inf",
           '"x"', "[]", "{}", "true", "1e30", "3.5", "-273.15", "9999999", "0.0001"]
EXPECTED = {
    "run": {"summary.json", "timeseries.csv", ".geartherm-output"},
    "run_summary": {"summary.json", ".geartherm-output"},
    "map": {"map.csv", "map.json", "map_efficiency.png", "map_total_loss.png", "map_oil_temp.png",
            "report.md", ".geartherm-output"},
    "map_no_plots": {"map.csv", "map.json", ".geartherm-output"},
    "bench": {"bench.csv", "bench.json", "work_precision.png", ".geartherm-output"},
    "rating": {"rating.csv", "rating.json", "rating.png", ".geartherm-output"},
    "rating_no_plots": {"rating.csv", "rating.json", ".geartherm-output"},
}
TEMPLATE_OF = {"run": "run", "map": "map", "bench": "bench", "rating": "rating"}


# A bundled model with switching controllers appended (a fan on the housing's convection and
# a thermostatic heater in the oil), so that mutations and `--set` reach [[thermal.controls]],
# and an oil/air cooler with a fixed-speed fan (`air_density_reference_c`).
CONTROLS = "helical_stage_controls.toml"
CONTROLS_TEXT = """
[[thermal.controls]]
name = "fan"
kind = "two_point"
sensor = "oil"
on_c = 70.0
off_c = 65.0
link = "housing-air"
off_fraction = 0.4

[[thermal.controls]]
name = "heater"
kind = "two_point"
sensor = "oil"
on_c = 20.0
off_c = 25.0
heater_w = 300.0

[[thermal.coolers]]
name = "oil_air"
hot = "oil"
cold = "ambient"
effectiveness = 0.5
capacity_rate_w_per_k = 20.0
air_density_reference_c = 15.0
thermostat = { open_c = 80.0, full_c = 95.0 }
"""
MODELS.append(CONTROLS)
GEAR[CONTROLS] = GEAR["helical_stage.toml"]


def model_texts(root):
    def text(m):
        if m == CONTROLS:
            return open(os.path.join(root, "models", "helical_stage.toml")).read() + CONTROLS_TEXT
        return open(os.path.join(root, "models", m)).read()
    return {m: text(m) for m in MODELS}


def mutate_model(text, rng):
    lines = text.split("\n")
    idx = [i for i, l in enumerate(lines) if "=" in l and not l.lstrip().startswith("#")]
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        k = rng.choice(idx)
        key = lines[k].split("=")[0]
        op = rng.random()
        if op < 0.7:
            lines[k] = f"{key}= {rng.choice(HOSTILE)}"
        elif op < 0.8:
            lines[k] = ""
        elif op < 0.9:
            lines[k] = f'{key}= "a\\nb,c\\"d"'
        else:
            lines[k] = lines[k] + "\n" + lines[k]
    return "\n".join(lines)


def extreme_model(text, rng):
    """Valid-looking but extreme: scale one numeric value by a large or small factor."""
    lines = text.split("\n")
    idx = [i for i, l in enumerate(lines)
           if re.match(r"^\s*\w+\s*=\s*-?[0-9.]+(e-?[0-9]+)?\s*(#.*)?$", l)]
    k = rng.choice(idx)
    key, val = lines[k].split("=", 1)
    val = val.split("#")[0].strip()
    try:
        v = float(val) * rng.choice([1e-6, 1e-3, 0.1, 10, 1e3, 1e6])
    except ValueError:
        return text
    lines[k] = f"{key}= {v!r}" if "." in val or "e" in val else f"{key}= {int(v) if abs(v) < 1e15 else v!r}"
    return "\n".join(lines)


def gen_cycle(rng):
    n = rng.randint(0, 6)
    t = 0.0
    if rng.random() < 0.5:
        rows = ["time_s,speed_kmh"]
        for _ in range(n):
            t += rng.choice([1e-12, 1e-3, 0.5, 1, 10, 1e6, -1])
            rows.append(f"{t},{rng.choice(HOSTILE + ['10', '50', '120', '499', '501'])}")
    else:
        rows = ["time_s,input_speed_rpm,input_torque_nm,gear"]
        for _ in range(n):
            t += rng.choice([1e-12, 1e-3, 0.5, 1, 10, 600])
            rows.append(f"{t},{rng.choice(HOSTILE + ['1000', '3000', '49999'])},"
                        f"{rng.choice(HOSTILE + ['10', '100', '-50'])},{rng.choice(['1', '3', 'x', ''])}")
    return "\n".join(rows) + "\n"


def gen_trace(rng):
    """A measured-trace CSV as `calibrate --trace` and `trace` read it: gaps in time, empty and
    hostile cells, columns missing or repeated."""
    cols = ["time_s", "input_speed_rpm", "input_torque_nm", "gear", "node:oil", "boundary:ambient"]
    if rng.random() < 0.2:
        cols = rng.sample(cols, rng.randint(1, len(cols))) + ([rng.choice(cols)] if rng.random() < 0.3 else [])
    rows, t = [",".join(cols)], 0.0
    for _ in range(rng.randint(0, 40)):
        t += rng.choice([1, 1, 1, 600, 1e-12, 0, -1, 1e6])
        good = {"input_speed_rpm": "1500", "input_torque_nm": "300", "gear": "1", "node:oil": "55.5",
                "boundary:ambient": "20", "time_s": str(t)}
        cells = [str(t)] + [good[c] if rng.random() < 0.95 else rng.choice([""] + HOSTILE) for c in cols[1:]]
        rows.append(",".join(cells[:len(cols)]))
    return "\n".join(rows) + "\n"


def base_args(cmd, m, rng, v, gear):
    """Options of `cmd` on model `m`: valid ones, each replaced by a hostile value with the
    chance `v` gives."""
    if cmd == "check":
        return ["check", "MODEL"]
    if cmd == "trace":
        return ["trace", "CYCLE"] + (["--json"] if rng.random() < 0.5 else []) + (
            ["--refuse-missing"] if rng.random() < 0.3 else [])
    if cmd == "info":
        return ["info", "MODEL"] + (["--json"] if rng.random() < 0.5 else [])
    if cmd == "losses":
        return ["losses", "MODEL", "--gear", gear, "--speed-rpm", v(["0", "100", "1450", "6000", "49999"]),
                "--torque-nm", v(["0", "0.1", "50", "300"]), "--oil-temp-c", v(["-20", "23", "90", "150"]), "--json"]
    if cmd == "steady":
        return ["steady", "MODEL", "--gear", gear, "--speed-rpm", v(["0", "500", "1450", "3000"]),
                "--torque-nm", v(["0", "0.1", "50", "200"]), "--json"]
    if cmd == "map":
        ax = lambda good: rng.choice(good) if rng.random() < 0.8 else rng.choice(
            ["1:2:0", "a:b:c", "5:1:3", "0:1e300:2", "0:100:100000"])
        args = ["map", "MODEL", "--gear", gear, "--speed-rpm", ax(["500:1500:2", "1000:1000:1", "100:3000:3"]),
                "--torque-nm", ax(["10:100:2", "0:0:1", "50:300:3"]), "--out", "OUT", "--quiet"]
        return args + (["--no-plots"] if rng.random() < 0.8 else [])
    if cmd == "rating":
        args = ["rating", "MODEL", "--gear", gear, "--speed-rpm", rng.choice(["1000", "500:3000:3", "0:1e300:2", "1000,2000", "x"])
                if rng.random() < 0.2 else rng.choice(["1000", "500:3000:3"]), "--oil-limit-c",
                v(["-30", "60", "90", "120", "199"]), "--out", "OUT", "--quiet"]
        if rng.random() < 0.3:
            args += ["--torque-max-nm", v(["50", "500", "1e6"])]
        if rng.random() < 0.2:
            args += ["--ambient-c", v(["-40", "23", "60"])]
        return args + (["--no-plots"] if rng.random() < 0.5 else [])
    if cmd == "bench":
        return ["bench", "MODEL", "--cycle", "RIG", "--repeats", v(["1"]), "--min-rtol", v(["1e-4", "1e-3"]),
                "--solvers", rng.choice(["ros3", "bdf", "ros3,tsit45", "nope"]), "--out", "OUT"]
    return None


def run_args(rng, v, case):
    if rng.random() < 0.7:
        case["cycle"] = gen_cycle(rng)
        cyc = "CYCLE"
    else:
        cyc = rng.choice(["wltc", "nedc", "nope", "DIR", "RIG"])
    args = ["run", "MODEL", "--cycle", cyc, "--out", "OUT", "--quiet", "--max-steps", rng.choice(["100", "100000"])]
    if rng.random() < 0.3:
        args += ["--rtol", v(["1e-3", "1e-6"])]
    if rng.random() < 0.3:
        args += ["--json"]
    if rng.random() < 0.2:
        args += ["--summary-only"]
    if rng.random() < 0.2:
        args += ["--initial-temp-c", v(["-30", "23", "120"])]
    if rng.random() < 0.1:
        args += ["--frozen-viscosity-c", v(["-60", "-40", "0", "40", "199"])]
    if rng.random() < 0.2:
        args += ["--spread"]
    return args


def make_case(i, rng, texts, family):
    m = rng.choice(MODELS)
    text = texts[m]
    if family == "cli":
        r = rng.random()
        if r < 0.45:
            text = mutate_model(text, rng)
        elif r < 0.65:
            text = extreme_model(text, rng)
    cmds = ["check", "info", "losses", "losses", "steady", "steady", "map", "run", "run", "rating"]
    cmds += ["trace"] if family == "cli" else []
    cmd = rng.choice(cmds + (["bench"] if family == "set" else []))
    gear = GEAR[m] if rng.random() < 0.9 else rng.choice(["0", "R", "x", "1\n"])
    hostile_p = 0.3 if family == "cli" else 0.05
    v = lambda good: rng.choice(HOSTILE) if rng.random() < hostile_p else rng.choice(good)
    case = {"id": i, "family": family, "model": m, "model_text": text, "cmd": cmd, "cycle": None}
    if cmd == "trace":
        case["cycle"] = gen_trace(rng)
    args = base_args(cmd, m, rng, v, gear) or run_args(rng, v, case)
    if family == "set":
        args[2:2] = set_args(rng, texts[m])
    case["args"] = args
    case["preload"] = cmd in TEMPLATE_OF and rng.random() < 0.5
    case["label"] = " ".join(args)
    return case


# ---------------------------------------------------------------------------------------------
# `--set` key paths and values

def leaf_paths(text):
    """Every leaf key path of a model (tables by key, arrays of named tables by ["name"], other
    arrays by index) with its value."""
    out = []

    def key(k):
        return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else '"' + k.replace('"', '\\"') + '"'

    def walk(v, path):
        if isinstance(v, dict):
            for k, x in v.items():
                walk(x, f"{path}.{key(k)}" if path else key(k))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for j, x in enumerate(v):
                sel = f'["{x["name"]}"]' if isinstance(x.get("name"), str) and '"' not in x["name"] else f"[{j}]"
                walk(x, path + sel)
        else:
            out.append((path, v))
            if isinstance(v, list) and v:
                out.append((f"{path}[{len(v) - 1}]", v[-1]))

    walk(tomllib.loads(text), "")
    return out


_PATHS = {}
BAD_PATHS = ["", ".", "..", "a..b", "x[", "x]", '["', "gears[", "gears[-1].x", "gears[99999999999999999999].x",
             'gears["nope"].face_width_mm', "model.name.x", "oil[0]", "oil.catalogue.x", "thermal.nodes[0][0]",
             "ü.ß", "lubrication.oil_level_mm ", " lubrication.oil_level_mm", "a" * 5000, "x\ny", "x=y",
             'thermal.links["housing-air"', "train", "[0]", '"unterminated', "gears[0].name", "model"]
BAD_VALUES = ["", "=", "[", "{", '"', "'''", "1 2", "1\n[model]\nname = \"x\"", "[1, [2, [3, [4]]]]",
              "{a = 1, b = {c = 2}}", "1979-05-27", "2e400", "0x10", "1_000", "+inf", "-nan", '"' + "x" * 10000 + '"',
              "[" * 200 + "]" * 200, "\"\\u0000\"", "\"a\\nb,c\\\"d\"", "18446744073709551616"]


def set_value(rng, orig):
    r = rng.random()
    if r < 0.2:
        return rng.choice(HOSTILE)
    if r < 0.65 and isinstance(orig, (int, float)) and not isinstance(orig, bool):
        moderate = rng.random() < 0.6
        x = orig * (rng.choice([0.5, 0.9, 1.1, 2]) if moderate else rng.choice([0, -1, 1e-9, 1e3, 1e9]))
        return repr(float(x)) if isinstance(orig, float) else str(int(x))
    if r < 0.75:
        return repr(orig).replace("'", '"').replace("True", "true").replace("False", "false")
    return rng.choice(BAD_VALUES)


def set_args(rng, text):
    paths = _PATHS.get(text)
    if paths is None:
        paths = _PATHS.setdefault(text, leaf_paths(text))
    out = []
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        path, orig = rng.choice(paths)
        r = rng.random()
        if r < 0.1:
            path = rng.choice(BAD_PATHS)
        elif r < 0.15:
            path = path + rng.choice([".x", "[0]", '["x"]', "[1000000]", ""])
        form = rng.random()
        val = set_value(rng, orig)
        arg = f"{path}={val}" if form < 0.9 else rng.choice([path, f"{path}=={val}", f"={val}", f"{path} = {val}"])
        out += ["--set", arg]
    return out


# ---------------------------------------------------------------------------------------------
# Running

def expected_set(case, args):
    cmd = case["cmd"]
    if cmd == "run":
        return EXPECTED["run_summary" if "--summary-only" in args else "run"]
    if cmd in ("map", "rating"):
        return EXPECTED[cmd + "_no_plots" if "--no-plots" in args else cmd]
    return EXPECTED.get(cmd)


def run_case(case, ctx):
    res = core.new_result(case)
    with tempfile.TemporaryDirectory(prefix="hostile_") as d:
        model = os.path.join(d, "m.toml")
        with open(model, "w") as f:
            f.write(case["model_text"])
        outparent = os.path.join(d, "outs")
        os.mkdir(outparent)
        out = os.path.join(outparent, "o")
        if case["preload"]:
            shutil.copytree(ctx.templates[TEMPLATE_OF[case["cmd"]]], out)
        before = core.snapshot(out)
        cycle = os.path.join(d, "c.csv")
        if case["cycle"] is not None:
            with open(cycle, "w") as f:
                f.write(case["cycle"])
        subs = {"MODEL": model, "OUT": out, "CYCLE": cycle, "DIR": d, "RIG": ctx.rig}
        args = [subs.get(a, a) for a in case["args"]]
        p = core.run([ctx.bin] + args, cwd=d, timeout=ctx.limit * (3 if case["cmd"] == "bench" else 1))
        core.classify(res, p, {0, 1, 2, 3})
        if p.timed_out:
            return res
        check_stdout(res, p, args, d)
        check_outputs(res, case, args, p.rc, out, outparent, before)
        core.stray_in(res, d, {"m.toml", "c.csv", "outs"})
    return res


def check_stdout(res, p, args, d):
    # The scratch path is random ([a-z0-9_]) and can spell "inf" or "nan" between digits: blank
    # it before looking for non-finite numbers in what was printed.
    stdout = p.out.decode(errors="replace").replace(d, "DIR")
    if "--json" in args:
        if p.rc == 0:
            core.check_json_text(res, stdout, "stdout")
        elif stdout.strip():
            res["classes"].append("stray")
            res["detail"] = "--json failure printed on stdout"
    elif p.rc == 0 and core.non_finite_in(stdout):
        res["classes"].append("non_finite")
        res["detail"] = "stdout"


def check_outputs(res, case, args, rc, out, outparent, before):
    if case["cmd"] not in TEMPLATE_OF:
        return
    beside = sorted(os.listdir(outparent))
    if rc != 0:
        if before:
            core.unchanged(res, before, out)
            if beside != ["o"]:
                res["classes"].append("stray")
                res["detail"] = f"exit {rc}: beside the target {beside}"
        elif beside:
            res["classes"].append("stray")
            res["detail"] = f"exit {rc} but wrote {beside}"
        return
    if beside != ["o"]:
        res["classes"].append("stray")
        res["detail"] = f"beside the target: {beside}"
    written = set(os.listdir(out)) if os.path.isdir(out) else set()
    if written != expected_set(case, args):
        res["classes"].append("stray")
        res["detail"] = f"result set {sorted(written)}"
    core.check_files(res, out)
