"""The Python API (family ``python``): bad arguments to every call (`Model.load`,
`Model.from_text`, `override`, `losses`, `steady`, `map`, `rating`, `run`, `study`), DataFrames, Series,
numpy scalars and arrays where numbers, lists or mappings belong, and every call once more
through a process pool, whose exceptions must arrive with their type, message and key path.

Each case is sent to a long-lived worker interpreter (``pyworker.py``), one per campaign
thread: a worker that dies is a ``crash``, one that does not answer within the limit a
``hang``; either is restarted for the next case."""
import json
import os
import subprocess
import sys
import threading

from .cli import HOSTILE, MODELS, mutate_model

R = lambda name: {"r": name}
NUMBERS = [R("nan"), R("inf"), R("-inf"), R("none"), R("object"), R("np_nan"), R("np_int"), R("np_float"),
           R("big_int"), R("neg_big_int"), R("bytes"), R("set"), R("complex"), R("neg_zero"), R("df"),
           R("series"), R("ndarray"), R("tuple"), R("bool"), "1450", "x", -1.0, 0.0, 1e308, -1e308, 5e-324,
           [1.0], {}, 1e30]
LISTS = [R("series"), R("ndarray"), R("df"), R("empty_df"), R("np_array_2d"), [], [R("nan")], "1000:2000:2",
         [1000.0] * 3000, R("none"), R("tuple"), [[1.0]], {"a": 1.0}]
PATHS = [R("none"), 123, R("bytes"), "", "/nonexistent/m.toml", R("path_dir"), R("dev_null"), R("nul"), R("long"),
         [1], R("df")]


def good_or(rng, good, bad, p=0.35):
    return rng.choice(bad) if rng.random() < p else good


def gen_values(rng, texts):
    """An override mapping: real paths with hostile values, or hostile keys."""
    from .cli import leaf_paths
    m = "fzg_c.toml"
    paths = leaf_paths(texts[m])
    out = {}
    for _ in range(rng.choice([1, 1, 2])):
        path, val = rng.choice(paths)
        if rng.random() < 0.15:
            path = rng.choice(["", "x", "gears[99].x", "a..b", "oil.catalogue.x", "\x00"])
        out[path] = rng.choice(NUMBERS + [val, "fva_3a", R("frame_params")])
    return out


def gen_call(rng, scenario, root, texts):
    a = {"root": root}
    if scenario == "load":
        a["path"] = rng.choice(PATHS + [os.path.join(root, "models", rng.choice(MODELS))])
    elif scenario == "from_text":
        t = texts[rng.choice(MODELS)]
        a["text"] = rng.choice([mutate_model(t, rng), t[: rng.randrange(len(t))], "", R("none"), R("bytes"), t])
        a["name"] = rng.choice(["m.toml", "", R("none"), R("nul"), "a/b\nc"])
    elif scenario == "override":
        a["values"] = rng.choice([gen_values(rng, texts), R("df"), R("series"), R("none"), [("a", 1)], {1: 2},
                                  {R("tuple").__repr__(): 1}])
    elif scenario == "losses":
        a["kwargs"] = {"gear": good_or(rng, "1", ["9", R("np_int"), R("none"), 1]),
                       "speed_rpm": good_or(rng, 1450.0, NUMBERS), "torque_nm": good_or(rng, 50.0, NUMBERS),
                       "oil_temp_c": good_or(rng, 60.0, NUMBERS + [-60.0, -35.0, 200.0, 200.5])}
    elif scenario == "steady":
        a["kwargs"] = {"gear": "1", "speed_rpm": good_or(rng, 1450.0, NUMBERS), "torque_nm": good_or(rng, 50.0, NUMBERS),
                       "vehicle_speed_kmh": good_or(rng, 0.0, NUMBERS, 0.15),
                       "ambient_c": good_or(rng, None, NUMBERS + [-60.0, 150.0], 0.2)}
    elif scenario == "map":
        a["kwargs"] = {"gear": "1", "speed_rpm": good_or(rng, [1000.0, 2000.0], LISTS),
                       "torque_nm": good_or(rng, [10.0, 50.0], LISTS), "ambient_c": good_or(rng, None, NUMBERS, 0.15)}
    elif scenario == "rating":
        a["kwargs"] = {"gear": "1", "speed_rpm": good_or(rng, rng.choice([1000.0, [1000.0, 2000.0]]), NUMBERS + LISTS),
                       "oil_limit_c": good_or(rng, rng.choice([60.0, 90.0, 120.0]), NUMBERS + [-60.0, -35.0, 200.5]),
                       "torque_max_nm": good_or(rng, None, NUMBERS, 0.2), "ambient_c": good_or(rng, None, NUMBERS, 0.15)}
    elif scenario == "run":
        a["kwargs"] = {"cycle": good_or(rng, "RIG", [R("none"), "", "nope", R("path_dir"), R("dev_null"), 1, R("df")]),
                       "summary_only": rng.random() < 0.5}
        for k in ("rtol", "atol", "initial_temp_c", "ambient_c", "max_steps", "frozen_viscosity_c", "solver"):
            if rng.random() < 0.25:
                a["kwargs"][k] = rng.choice(NUMBERS + ["bdf", "nope", 100, -35.0, 0.0])
    else:
        gen_study(rng, a)
    if rng.random() < 0.3 and scenario in ("losses", "steady", "map", "rating", "run"):
        a["values"] = gen_values(rng, texts)
    return a


def gen_study(rng, a):
    good = {"lubrication.oil_level_mm": {"values": [40.0, 50.0]}}
    a["parameters"] = good_or(rng, good, [R("frame_params"), R("df"), R("series"), [1, 2], ["x"], {"x": 1},
                                          {"lubrication.oil_level_mm": R("df")}, {}, R("none"),
                                          {"lubrication.oil_level_mm": {"range": [R("nan"), 1.0]}}])
    a["job"] = good_or(rng, {"kind": "steady", "points": [{"gear": "1", "speed_rpm": 1450.0, "torque_nm": 50.0}]},
                       [{"kind": "nope"}, R("df"), {"kind": "run", "cycles": R("series")}, {"kind": "run", "cycles": []},
                        {"kind": "steady", "points": R("df")}, {"kind": "map", "gear": "1", "speed_rpm": R("ndarray"),
                                                                 "torque_nm": [1.0]}, "x"])
    a["sampling"] = good_or(rng, None, [{"plan": "lhs", "cases": R("np_int")}, {"plan": "lhs", "cases": 10 ** 8},
                                        {"plan": "nope"}, R("df"), {"plan": "lhs", "cases": R("nan")}], 0.2)
    kw = {}
    if rng.random() < 0.4:
        kw["cases"] = rng.choice([[0], [-1], [10 ** 20], ["a"], [R("nan")], R("ndarray"), R("series"), R("df"), [0, 0],
                                  [], R("none")])
    if rng.random() < 0.2:
        kw["name"] = rng.choice(["", "../x", R("none"), "a/b", R("long")])
    if rng.random() < 0.2:
        kw["threads_per_task"] = rng.choice([0, -1, 10 ** 6, R("nan"), "2", R("none")])
    a["kwargs"] = kw


SCENARIOS = ["load", "from_text", "override", "losses", "losses", "steady", "map", "rating", "run", "run", "study",
             "study"]


def make_case(i, rng, root, texts):
    scenario = rng.choice(SCENARIOS)
    a = gen_call(rng, scenario, root, texts)
    case = {"id": i, "family": "python", "scenario": scenario, "args": a, "pool": rng.random() < 0.2}
    case["label"] = f"python {scenario}{' via pool' if case['pool'] else ''}: " + json.dumps(a)[:300]
    return case


class Worker:
    """One worker interpreter, restarted after a crash or a hang."""

    def __init__(self, python, here):
        self.python, self.here, self.p = python, here, None

    def start(self):
        env = dict(os.environ, PYTHONPATH=os.path.dirname(self.here))
        self.p = subprocess.Popen([self.python, "-m", "hostile.pyworker"], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True,
                                  start_new_session=True, cwd=os.path.dirname(self.here))
        threading.Thread(target=self.p.stderr.read, daemon=True).start()

    def stop(self):
        if self.p is not None:
            try:
                os.killpg(self.p.pid, 9)
            except ProcessLookupError:
                pass
            self.p.wait()
            self.p = None

    def ask(self, case, limit):
        if self.p is None or self.p.poll() is not None:
            self.start()
        line = json.dumps({"id": case["id"], "scenario": case["scenario"], "args": case["args"], "pool": case["pool"]})
        answer = [None]

        def read():
            answer[0] = self.p.stdout.readline()

        try:
            self.p.stdin.write(line + "\n")
            self.p.stdin.flush()
        except BrokenPipeError:
            self.stop()
            return {"classes": ["crash"], "detail": "the worker died before the case"}
        t = threading.Thread(target=read, daemon=True)
        t.start()
        t.join(limit)
        if t.is_alive():
            self.stop()
            return {"classes": ["hang"]}
        if not answer[0]:
            code = self.p.wait()
            self.p = None
            return {"classes": ["crash"], "detail": f"the worker died (exit {code})"}
        return json.loads(answer[0])


_LOCAL = threading.local()


def run_case(case, ctx):
    w = getattr(_LOCAL, "worker", None)
    if w is None:
        w = _LOCAL.worker = Worker(ctx.python, os.path.dirname(os.path.abspath(__file__)))
        ctx.workers.append(w)
    case["args"] = json.loads(json.dumps(case["args"]).replace('"RIG"', json.dumps(ctx.rig)))
    r = w.ask(case, ctx.limit * (6 if case["scenario"] == "study" or case["pool"] else 2))
    res = {"id": case["id"], "family": "python", "cmd": case["label"], "classes": r.get("classes", []),
           "rc": r.get("outcome", "-") + ("" if "type" not in r else f" {r['type']}")}
    if r.get("detail"):
        res["detail"] = r["detail"]
    return res
