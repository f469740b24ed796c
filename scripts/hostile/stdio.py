"""Unwritable standard output and standard error (family ``stdio``): every command with its
stdout or stderr on a full device (/dev/full), a pipe whose reader has gone, a descriptor open
for reading only, or closed.

The contract: the exit code does not depend on whether stderr can be written; an unwritable
stdout is exit 3 (a closed pipe: exit 141, quietly) for a command that prints, and the command
then keeps the previous result set of its output directory byte for byte; a closed descriptor
is reopened on /dev/null by the Rust runtime, so the command behaves as with a writable one.
The reference exit code is the same command's with both streams writable."""
import os
import shutil
import subprocess
import tempfile

from . import core
from .cli import GEAR, MODELS

MODES = ["full", "pipe", "readonly", "closed"]


def command(rng, m):
    gear = GEAR[m]
    return rng.choice([
        ["check", "MODEL"],
        ["info", "MODEL", "--json"],
        ["info", "MODEL"],
        ["losses", "MODEL", "--gear", gear, "--speed-rpm", "1450", "--torque-nm", "50", "--oil-temp-c", "60", "--json"],
        ["losses", "MODEL", "--gear", "9", "--speed-rpm", "1450", "--torque-nm", "50", "--oil-temp-c", "60"],
        ["steady", "MODEL", "--gear", gear, "--speed-rpm", "1450", "--torque-nm", "50"],
        ["steady", "MODEL", "--gear", gear, "--speed-rpm", "1450", "--torque-nm", "50", "--json"],
        ["map", "MODEL", "--gear", gear, "--speed-rpm", "1000:2000:2", "--torque-nm", "10:50:2", "--out", "OUT",
         "--no-plots"],
        ["run", "MODEL", "--cycle", "RIG", "--out", "OUT"],
        ["run", "MODEL", "--cycle", "RIG", "--out", "OUT", "--json", "--summary-only"],
        ["run", "MODEL", "--cycle", "nope", "--out", "OUT"],
        ["run", "MODEL", "--cycle", "RIG", "--frozen-viscosity-c", "0", "--out", "OUT"],
        ["report", "RUNDIR"],
        ["rating", "MODEL", "--gear", gear, "--speed-rpm", "1000:2000:2", "--oil-limit-c", "90", "--out", "OUT"],
        ["rating", "MODEL", "--gear", gear, "--speed-rpm", "1000", "--oil-limit-c", "90", "--json"],
        ["bench", "MODEL", "--cycle", "RIG", "--repeats", "1", "--min-rtol", "1e-4", "--solvers", "ros3",
         "--out", "OUT"],
        ["study", "STUDY", "--list"],
        ["study", "STUDY", "--out", "OUT"],
        ["validate", "VALIDATION", "--out", "OUT"],
        ["validate", "VALIDATION", "--out", "OUT", "--json"],
        ["--help"],
        ["run", "--help"],
        ["--version"],
    ])


def make_case(i, rng):
    m = rng.choice(MODELS)
    args = command(rng, m)
    which = rng.choice(["stdout", "stdout", "stderr", "both"])
    case = {"id": i, "family": "stdio", "model": m, "args": args, "which": which,
            "mode": rng.choice(MODES), "preload": "OUT" in args and rng.random() < 0.7}
    case["label"] = f"{which}={case['mode']}: " + " ".join(args)
    return case


def template_for(args):
    cmd = args[0]
    return {"run": "run", "map": "map", "bench": "bench", "study": "study", "validate": "validate",
            "rating": "rating"}.get(cmd)


def stream(mode, d, tag):
    """A file descriptor for `mode` (None: closed), and what to close after the run."""
    if mode == "full":
        fd = os.open("/dev/full", os.O_WRONLY)
        return fd, [fd]
    if mode == "pipe":
        r, w = os.pipe()
        os.close(r)
        return w, [w]
    if mode == "readonly":
        path = os.path.join(d, f".ro-{tag}")
        open(path, "w").close()
        fd = os.open(path, os.O_RDONLY)
        return fd, [fd]
    return None, []


def run_with(ctx, argv, cwd, out_mode, err_mode, d):
    """Run with the given stdout/stderr modes ("ok": a pipe read by us)."""
    fds, close = {}, []
    for name, mode in (("stdout", out_mode), ("stderr", err_mode)):
        if mode == "ok":
            fds[name] = subprocess.PIPE
        elif mode == "closed":
            fds[name] = None
        else:
            fd, c = stream(mode, d, name)
            fds[name], close = fd, close + c
    if "closed" in (out_mode, err_mode):
        return run_closed(ctx, argv, cwd, out_mode, err_mode, fds)
    try:
        return core.run(argv, cwd=cwd, timeout=ctx.limit * 2, stdout=fds["stdout"], stderr=fds["stderr"])
    finally:
        for fd in close:
            os.close(fd)


def run_closed(ctx, argv, cwd, out_mode, err_mode, fds):
    """A closed descriptor: the shell closes it (`>&-`, `2>&-`) before exec."""
    redir = (" >&-" if out_mode == "closed" else "") + (" 2>&-" if err_mode == "closed" else "")
    sh = " ".join(shlex_quote(a) for a in core.limited(argv)) + redir
    return core.run(["/bin/sh", "-c", "exec " + sh], cwd=cwd, timeout=ctx.limit * 2,
                    stdout=fds["stdout"] if out_mode != "closed" else subprocess.DEVNULL,
                    stderr=fds["stderr"] if err_mode != "closed" else subprocess.DEVNULL)


def shlex_quote(s):
    import shlex
    return shlex.quote(s)


def allowed_codes(case, ref):
    out_mode = case["mode"] if case["which"] in ("stdout", "both") else "ok"
    codes = {ref}
    if out_mode in ("full", "readonly"):
        codes.add(3)
    elif out_mode == "pipe":
        codes.add(141)
    return codes


def run_case(case, ctx):
    res = core.new_result(case)
    d = tempfile.mkdtemp(prefix="hostile_stdio_")
    try:
        out = os.path.join(d, "outs", "o")
        os.mkdir(os.path.join(d, "outs"))
        rundir = os.path.join(d, "rundir")
        shutil.copytree(ctx.templates["run"], rundir)
        subs = {"MODEL": os.path.join(ctx.root, "models", case["model"]), "OUT": out, "RIG": ctx.rig,
                "RUNDIR": rundir, "STUDY": ctx.study_file, "VALIDATION": os.path.join(ctx.root, "validation")}
        argv = [ctx.bin] + [subs.get(a, a) for a in case["args"]]
        ref = core.run(argv, cwd=d, timeout=ctx.limit * 2)
        if ref.timed_out:
            res["classes"].append("hang")
            return res
        shutil.rmtree(out, ignore_errors=True)
        shutil.rmtree(rundir)
        shutil.copytree(ctx.templates["run"], rundir)
        tpl = template_for(case["args"])
        if case["preload"] and tpl:
            shutil.copytree(ctx.templates[tpl], out)
        before = core.snapshot(out)
        before_run = core.snapshot(rundir)
        out_mode = case["mode"] if case["which"] in ("stdout", "both") else "ok"
        err_mode = case["mode"] if case["which"] in ("stderr", "both") else "ok"
        p = run_with(ctx, argv, d, out_mode, err_mode, d)
        core.classify(res, p, allowed_codes(case, ref.rc))
        if p.timed_out:
            return res
        if p.rc == 141 and (b"Broken pipe" in p.err or b"standard output" in p.err):
            res["classes"].append("stray")
            res["detail"] = f"exit 141 is quiet, but printed: {p.err[-200:]!r}"
        # A study fills its directory in place (journal, then table): what it finished stays.
        if p.rc != 0 and case["args"][0] != "study":
            core.unchanged(res, before, out)
            if case["args"][0] == "report":
                core.unchanged(res, before_run, rundir)
            core.stray_in(res, os.path.join(d, "outs"), {"o"} if before else set())
        core.stray_in(res, os.path.join(d, "outs"), {"o"})
    finally:
        shutil.rmtree(d, ignore_errors=True)
    return res
