"""Crafted inputs to `report` (family ``report``): a run, map or bench directory whose
summary.json, map.json, bench.json or CSV files were edited — numbers at and beyond every
limit (1e308, −1e308, 0, NaN and infinities as text), efficiencies outside [0, 1], wrong types,
missing and unknown keys, ragged and duplicated rows, truncated and non-UTF-8 files, deep
nesting, directories, FIFOs and device links in place of files.

The contract: exit 0 (report.md and the plots beside the data, every number finite, every
efficiency a fraction in [0, 1] shown as a percentage in [0, 100]) or 1 (invalid input, naming
the user's file, not the transaction's temporary copy) or 3 (I/O); on failure the directory
is left byte for byte."""
import json
import os
import re
import shutil
import tempfile

from . import core

KINDS = {"run": ("summary.json", "timeseries.csv"), "map": ("map.json", "map.csv"),
         "bench": ("bench.json", "bench.csv")}
NUMBERS = [1e308, -1e308, 0.0, -1.0, 2.0, 1e-308, 5e-324, 1e30, -0.0, 123456789012345678901234567890.0]
TEXTS = ["NaN", "Infinity", "-Infinity", "nan", "inf", "-inf", "1e999", "", "x", "null", "true", "[]", "{}",
         '"1.0"', "0x10", "1,5"]


def json_craft(rng, doc):
    """One edit of a JSON document (as text: NaN and infinities are not JSON)."""
    keys = leaf_keys(doc)
    if not keys:
        return json.dumps(doc)
    path = rng.choice(keys)
    r = rng.random()
    if r < 0.45:
        set_at(doc, path, rng.choice(NUMBERS))
        return json.dumps(doc)
    if r < 0.6:
        set_at(doc, path, "@@RAW@@")
        return json.dumps(doc).replace('"@@RAW@@"', rng.choice(TEXTS) or '""')
    if r < 0.7:
        set_at(doc, path, rng.choice([None, "x", [], {}, True, [1.0, 2.0]]))
        return json.dumps(doc)
    if r < 0.8:
        del_at(doc, path)
        return json.dumps(doc)
    if r < 0.85:
        doc["unknown_key_x"] = 1
        return json.dumps(doc)
    text = json.dumps(doc)
    return rng.choice([text[: rng.randrange(len(text) + 1)], "\ufeff" + text, "[" * 100000 + "]" * 100000,
                       "", text.replace("0", "\u0660", 3), text + "garbage"])


def leaf_keys(v, path=()):
    out = []
    if isinstance(v, dict):
        for k, x in v.items():
            out += leaf_keys(x, path + (k,)) or [path + (k,)]
    elif isinstance(v, list):
        for i, x in enumerate(v[:20]):
            out += leaf_keys(x, path + (i,)) or [path + (i,)]
    return out


def set_at(doc, path, value):
    for p in path[:-1]:
        doc = doc[p]
    doc[path[-1]] = value


def del_at(doc, path):
    for p in path[:-1]:
        doc = doc[p]
    if isinstance(doc, dict):
        del doc[path[-1]]
    else:
        doc.pop(path[-1])


def csv_craft(rng, text):
    lines = text.split("\n")
    body = [k for k in range(1, len(lines)) if lines[k]]
    r = rng.random()
    if r < 0.5 and body:
        for _ in range(rng.choice([1, 1, 2, 10])):
            k = rng.choice(body)
            cells = lines[k].split(",")
            j = rng.randrange(len(cells))
            cells[j] = rng.choice([repr(x) for x in NUMBERS] + TEXTS)
            lines[k] = ",".join(cells)
    elif r < 0.6 and body:
        k = rng.choice(body)
        lines[k] = rng.choice([lines[k] + ",1", ",".join(lines[k].split(",")[:-1]), "", "\x00" * 10])
    elif r < 0.7:
        hdr = lines[0].split(",")
        j = rng.randrange(len(hdr))
        hdr[j] = rng.choice(["", hdr[0], "efficiency", "x,y", "temp_oil_c", hdr[j] + " "])
        lines[0] = ",".join(hdr)
    elif r < 0.8:
        lines = rng.choice([lines[:1], lines[:2], [], lines[:1] + lines[1:][::-1], lines + lines[1:]])
    elif r < 0.9:
        return "\r\n".join(lines).encode()
    else:
        return rng.choice([b"\xff\xfe\x00garbage", "\ufeff".encode() + text.encode(), text.encode()[: len(text) // 2],
                           (lines[0] + "\n" + ("1," * 100000) + "\n").encode()])
    return "\n".join(lines).encode()


def diagonal(rng, path):
    """n rows of n distinct speeds and torques: an n × n grid for n points."""
    with open(path) as f:
        lines = f.read().split("\n")
    tail = lines[1].split(",")[2:]
    n = rng.choice([300, 5000, 70000])
    rows = [",".join([str(1000.0 + k), str(10.0 + k)] + tail) for k in range(n)]
    with open(path, "w") as f:
        f.write("\n".join([lines[0]] + rows) + "\n")


def make_case(i, rng):
    kind = rng.choice(["run", "run", "map", "bench"])
    target = rng.choice(["json", "csv", "csv", "both", "special"])
    case = {"id": i, "family": "report", "kind": kind, "target": target, "seed": rng.randrange(2 ** 62),
            "label": f"report {kind} {target}"}
    return case


def craft(case, rng, d):
    meta, table = KINDS[case["kind"]]
    mp, tp = os.path.join(d, meta), os.path.join(d, table)
    t = case["target"]
    if t in ("json", "both") and os.path.exists(mp):
        with open(mp) as f:
            text = json_craft(rng, json.load(f))
        with open(mp, "w") as f:
            f.write(text)
    if t in ("csv", "both") and case["kind"] == "map" and rng.random() < 0.05:
        diagonal(rng, tp)
    elif t in ("csv", "both"):
        with open(tp) as f:
            data = csv_craft(rng, f.read())
        with open(tp, "wb") as f:
            f.write(data)
    if t == "special":
        victim = rng.choice([mp, tp])
        os.remove(victim)
        how = rng.choice(["dir", "fifo", "zero", "loop", "missing", "foreign"])
        if how == "dir":
            os.mkdir(victim)
        elif how == "fifo":
            os.mkfifo(victim)
        elif how == "zero":
            os.symlink("/dev/zero", victim)
        elif how == "loop":
            os.symlink(victim, victim)
        elif how == "foreign":
            with open(os.path.join(d, "notes.txt"), "w") as f:
                f.write("mine")
        case["label"] += f" {how} {os.path.basename(victim)}"


def run_case(case, ctx):
    import random
    res = core.new_result(case)
    rng = random.Random(case["seed"])
    base = tempfile.mkdtemp(prefix="hostile_report_")
    try:
        d = os.path.join(base, "r")
        shutil.copytree(ctx.templates[case["kind"]], d, symlinks=True)
        craft(case, rng, d)
        res["cmd"] = case["label"]
        before = core.snapshot(d)
        p = core.run([ctx.bin, "report", d], cwd=base, timeout=ctx.limit)
        core.classify(res, p, {0, 1, 3})
        if p.timed_out:
            return res
        if p.rc != 0:
            core.unchanged(res, before, d)
        else:
            check_report(res, d, p, case["kind"])
            data = lambda snap: {k: v for k, v in snap.items() if k.endswith((".csv", ".json"))}
            if data(core.snapshot(d)) != data(before):
                res["classes"].append("changed_on_failure")
                res["detail"] = "report changed its input files"
        core.stray_in(res, base, {"r"})
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return res


PCT = re.compile(r"(-?[0-9.]+(?:e[-+]?[0-9]+)?) ?%")


def check_report(res, d, p, kind):
    md = os.path.join(d, "report.md")
    if kind == "bench":
        if not os.path.isfile(os.path.join(d, "work_precision.png")):
            res["classes"].append("stray")
            res["detail"] = "exit 0 without work_precision.png"
        return
    if not os.path.isfile(md):
        res["classes"].append("stray")
        res["detail"] = "exit 0 without report.md"
        return
    with open(md, errors="replace") as f:
        text = f.read()
    if core.non_finite_in(text):
        res["classes"].append("non_finite")
        res["detail"] = "report.md: " + core.NUM_RE.search(text).group(0)
    for line in text.splitlines():
        if "efficiency" in line.lower():
            for m in PCT.finditer(line):
                try:
                    v = float(m.group(1))
                except ValueError:
                    continue
                if not (0.0 <= v <= 100.0):
                    res["classes"].append("efficiency")
                    res["detail"] = f"report.md: {line.strip()[:120]}"
    if core.non_finite_in(p.out.decode(errors="replace").replace(d, "DIR")):
        res["classes"].append("non_finite")
        res["detail"] = "stdout"
