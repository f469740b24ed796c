#!/usr/bin/env python3
"""Hostile-input campaign: generated invalid or extreme inputs through `check`,
`info`, `losses`, `steady`, `map` and `run`, counting what must never happen.

    python3 scripts/hostile_campaign.py --cases 100000 --jobs 2 [--bin target/release/geartherm]

Each case is one command on a generated input (a model file with one mutated key, a generated
cycle, extreme or malformed command-line values), run with a 10 s limit in its own scratch
directory. Counted failures:

- panic (exit 101), abort (signal: SIGABRT, SIGSEGV, ...), hang (killed after 10 s);
- exit code outside {0, 1, 2, 3};
- non-finite number written (NaN / inf / null number in a written CSV, JSON or Markdown file,
  or in `--json` stdout);
- efficiency outside [0, 1] (any `efficiency` field or column written or printed);
- stray or mixed files: files written although the command failed, anything beside the output
  directory, a result set that is not exactly the expected one, `--json` stdout that is not one
  JSON document.

Prints the counts and the first examples of each class; exit 1 if any failure class is nonzero.
Outside the test suite: not run by CI (it takes long on 2 cores).
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = ["fzg_c.toml", "at6_lepelletier.toml", "helical_stage.toml", "pt6_spur_pair.toml"]
GEAR = {"fzg_c.toml": "1", "at6_lepelletier.toml": "3", "helical_stage.toml": "1", "pt6_spur_pair.toml": "1"}
HOSTILE = ["0", "-0.0", "-1", "1e308", "-1e308", "1e-308", "1e-300", "1e100", "nan", "inf", "-inf",
           '"x"', "[]", "{}", "true", "1e30", "3.5", "-273.15", "9999999", "0.0001"]
NUM_RE = re.compile(r"(?<![A-Za-z_])(nan|NaN|-?inf|-?Infinity)(?![A-Za-z_])")
FINITE_LIMIT_S = 10

RUN_EXPECTED = {"summary.json", "timeseries.csv", ".geartherm-output"}
MAP_EXPECTED = {"map.csv", "map.json", "map_efficiency.png", "map_total_loss.png",
                "map_oil_temp.png", "report.md", ".geartherm-output"}


def model_texts():
    return {m: open(os.path.join(ROOT, "models", m)).read() for m in MODELS}


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
    kind = rng.random()
    n = rng.randint(0, 6)
    t = 0.0
    if kind < 0.5:
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


def make_case(i, seed, texts):
    rng = random.Random(seed * 1_000_003 + i)
    m = rng.choice(MODELS)
    text = texts[m]
    r = rng.random()
    if r < 0.45:
        text = mutate_model(text, rng)
    elif r < 0.65:
        text = extreme_model(text, rng)
    cmd = rng.choice(["check", "info", "losses", "losses", "steady", "steady", "map", "run", "run"])
    gear = GEAR[m] if rng.random() < 0.9 else rng.choice(["0", "R", "x", "1\n"])
    v = lambda good: rng.choice(HOSTILE) if rng.random() < 0.3 else rng.choice(good)
    case = {"id": i, "model_text": text, "cmd": cmd, "cycle": None}
    if cmd == "check":
        args = ["check", "MODEL"]
    elif cmd == "info":
        args = ["info", "MODEL"] + (["--json"] if rng.random() < 0.5 else [])
    elif cmd == "losses":
        args = ["losses", "MODEL", "--gear", gear, "--speed-rpm", v(["0", "100", "1450", "6000", "49999"]),
                "--torque-nm", v(["0", "0.1", "50", "300"]), "--oil-temp-c", v(["-20", "23", "90", "150"]), "--json"]
    elif cmd == "steady":
        args = ["steady", "MODEL", "--gear", gear, "--speed-rpm", v(["0", "500", "1450", "3000"]),
                "--torque-nm", v(["0", "0.1", "50", "200"]), "--json"]
    elif cmd == "map":
        ax = lambda good: rng.choice(good) if rng.random() < 0.8 else rng.choice(["1:2:0", "a:b:c", "5:1:3", "0:1e300:2", "0:100:100000"])
        args = ["map", "MODEL", "--gear", gear, "--speed-rpm", ax(["500:1500:2", "1000:1000:1", "100:3000:3"]),
                "--torque-nm", ax(["10:100:2", "0:0:1", "50:300:3"]), "--out", "OUT", "--no-plots", "--quiet"]
        if rng.random() < 0.2:
            args.remove("--no-plots")
    else:
        if rng.random() < 0.7:
            case["cycle"] = gen_cycle(rng)
            cyc = "CYCLE"
        else:
            cyc = rng.choice(["wltc", "nedc", "nope", "DIR"])
        args = ["run", "MODEL", "--cycle", cyc, "--out", "OUT", "--quiet", "--max-steps", rng.choice(["100", "100000"])]
        if rng.random() < 0.3:
            args += ["--rtol", v(["1e-3", "1e-6"])]
        if rng.random() < 0.3:
            args += ["--json"]
        if rng.random() < 0.2:
            args += ["--summary-only"]
        if rng.random() < 0.2:
            args += ["--initial-temp-c", v(["-30", "23", "120"])]
    case["args"] = args
    return case


def non_finite_in(text):
    return bool(NUM_RE.search(text))


def json_non_finite(v, path=""):
    """Paths of nulls that stand for numbers and of efficiencies outside [0, 1]."""
    bad_nf, bad_eff = [], []
    if isinstance(v, dict):
        for k, x in v.items():
            p = f"{path}.{k}"
            if "efficiency" in k:
                if isinstance(x, (int, float)) and not (0.0 <= x <= 1.0):
                    bad_eff.append(p)
            if x is None and k.endswith(("_w", "_j", "_c", "_s", "_k")):
                bad_nf.append(p)
            a, b = json_non_finite(x, p)
            bad_nf += a
            bad_eff += b
    elif isinstance(v, list):
        for i, x in enumerate(v):
            a, b = json_non_finite(x, f"{path}[{i}]")
            bad_nf += a
            bad_eff += b
    return bad_nf, bad_eff


def csv_checks(path):
    nf, eff = False, False
    with open(path, errors="replace") as f:
        header = f.readline().rstrip("\n").split(",")
        cols = [i for i, h in enumerate(header) if h == "efficiency"]
        for line in f:
            cells = line.rstrip("\n").split(",")
            if len(cells) != len(header):
                return True, False, True
            for c in cells:
                if non_finite_in(c):
                    nf = True
            for i in cols:
                if cells[i]:
                    try:
                        e = float(cells[i])
                        if not (0.0 <= e <= 1.0):
                            eff = True
                    except ValueError:
                        nf = True
    return nf, eff, False


def run_case(case, binary):
    res = {"id": case["id"], "cmd": " ".join(case["args"]), "classes": []}
    with tempfile.TemporaryDirectory(prefix="hostile_") as d:
        model = os.path.join(d, "m.toml")
        with open(model, "w") as f:
            f.write(case["model_text"])
        outparent = os.path.join(d, "outs")
        os.mkdir(outparent)
        out = os.path.join(outparent, "o")
        cycle = os.path.join(d, "c.csv")
        if case["cycle"] is not None:
            with open(cycle, "w") as f:
                f.write(case["cycle"])
        subs = {"MODEL": model, "OUT": out, "CYCLE": cycle, "DIR": d}
        args = [subs.get(a, a) for a in case["args"]]
        try:
            p = subprocess.run([binary] + args, capture_output=True, timeout=FINITE_LIMIT_S, cwd=d)
        except subprocess.TimeoutExpired:
            res["classes"].append("hang")
            return res
        rc = p.returncode
        res["rc"] = rc
        err = p.stderr.decode(errors="replace")
        if rc == 101 or "panicked" in err:
            res["classes"].append("panic")
        elif rc < 0:
            res["classes"].append("abort")
        elif rc not in (0, 1, 2, 3):
            res["classes"].append("bad_exit")
        # The scratch path is random ([a-z0-9_]) and can spell "inf" or "nan" between digits:
        # blank it before looking for non-finite numbers in what was printed.
        stdout = p.stdout.decode(errors="replace").replace(d, "DIR")
        if "--json" in args:
            if rc == 0:
                try:
                    doc = json.loads(stdout)
                    nf, eff = json_non_finite(doc)
                    if nf:
                        res["classes"].append("non_finite")
                        res["detail"] = nf[:3]
                    if eff:
                        res["classes"].append("efficiency")
                        res["detail"] = eff[:3]
                except json.JSONDecodeError:
                    res["classes"].append("stray")
                    res["detail"] = "stdout is not one JSON document"
            elif stdout.strip():
                res["classes"].append("stray")
                res["detail"] = "--json failure printed on stdout"
        elif rc == 0 and non_finite_in(stdout):
            res["classes"].append("non_finite")
            res["detail"] = "stdout"
        # Files.
        beside = sorted(os.listdir(outparent))
        written = sorted(os.listdir(out)) if os.path.isdir(out) else []
        if case["cmd"] in ("run", "map"):
            if rc != 0 and (written or beside):
                res["classes"].append("stray")
                res["detail"] = f"exit {rc} but wrote {beside} {written}"
            if rc == 0:
                if beside != ["o"]:
                    res["classes"].append("stray")
                    res["detail"] = f"beside the target: {beside}"
                exp = MAP_EXPECTED if case["cmd"] == "map" else RUN_EXPECTED
                if case["cmd"] == "map" and "--no-plots" in args:
                    exp = {"map.csv", "map.json", ".geartherm-output"}
                if case["cmd"] == "run" and "--summary-only" in args:
                    exp = {"summary.json", ".geartherm-output"}
                if set(written) != exp:
                    res["classes"].append("stray")
                    res["detail"] = f"result set {written}"
                for n in written:
                    fp = os.path.join(out, n)
                    if n.endswith(".csv"):
                        nf, eff, ragged = csv_checks(fp)
                        if nf:
                            res["classes"].append("non_finite")
                        if eff:
                            res["classes"].append("efficiency")
                        if ragged:
                            res["classes"].append("stray")
                            res["detail"] = f"{n}: ragged rows"
                    elif n.endswith(".json"):
                        try:
                            doc = json.load(open(fp))
                        except json.JSONDecodeError:
                            res["classes"].append("non_finite")
                            continue
                        nf, eff = json_non_finite(doc)
                        if nf:
                            res["classes"].append("non_finite")
                            res["detail"] = nf[:3]
                        if eff:
                            res["classes"].append("efficiency")
                    elif n.endswith(".md") and non_finite_in(open(fp).read()):
                        res["classes"].append("non_finite")
        # Nothing written into the scratch dir except our inputs and the output parent.
        extra = set(os.listdir(d)) - {"m.toml", "c.csv", "outs"}
        if extra:
            res["classes"].append("stray")
            res["detail"] = f"stray in cwd: {sorted(extra)}"
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "geartherm"))
    a = ap.parse_args()
    texts = model_texts()
    counts = {k: 0 for k in ["panic", "abort", "hang", "bad_exit", "non_finite", "efficiency", "stray"]}
    exits = {}
    by_cmd = {}
    examples = {}
    done = 0
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = [ex.submit(run_case, make_case(i, a.seed, texts), a.bin) for i in range(a.cases)]
        for f in cf.as_completed(futs):
            r = f.result()
            done += 1
            exits[r.get("rc", "killed")] = exits.get(r.get("rc", "killed"), 0) + 1
            c = r["cmd"].split()[0]
            by_cmd[c] = by_cmd.get(c, 0) + 1
            for k in set(r["classes"]):
                counts[k] += 1
                examples.setdefault(k, []).append(r)
            if done % 1000 == 0:
                print(f"{done} cases: {counts}", file=sys.stderr, flush=True)
    print(f"cases run: {done} (seed {a.seed}, jobs {a.jobs})")
    print(f"commands: {dict(sorted(by_cmd.items()))}")
    print(f"exit codes: {dict(sorted(exits.items(), key=lambda x: str(x[0])))}")
    for k, n in counts.items():
        print(f"{k:>11}: {n}")
    for k, ex in examples.items():
        for r in ex[:3]:
            print(f"  e.g. {k}: case {r['id']} exit {r.get('rc')}: {r['cmd']} {r.get('detail', '')}")
    sys.exit(1 if any(counts.values()) else 0)


if __name__ == "__main__":
    main()
