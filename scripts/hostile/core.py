"""What every family of the hostile campaign shares: running one command under limits, the
failure classes, and the checks of what a command wrote.

Failure classes (each case reports the set it fell into; the campaign counts them):

- ``panic``: exit 101 or a Rust panic message; ``crash``: killed by a signal (SIGSEGV, SIGABRT,
  …) or, for the Python API, the interpreter died or a Rust panic surfaced as an exception;
- ``hang``: still running after the case's time limit (killed);
- ``wrong_exit``: an exit code the case does not allow (outside 0–3, or not the code the
  contract gives: 3 for an unwritable stdout, 141 for a closed pipe, …);
- ``non_finite``: NaN or an infinity in a written file or a printed JSON document;
- ``efficiency``: an efficiency outside [0, 1] written or printed;
- ``stray``: files written although the command failed, anything beside the output directory or
  in the working directory, a result set that is not the expected one, ragged CSV rows, a
  ``--json`` stdout that is not one document, a study table without every case exactly once;
- ``changed_on_failure``: a failed command changed the previous result set in its output
  directory (not byte for byte the same);
- ``bad_message``: a message that names the transaction's temporary copy instead of the user's
  directory.
"""
import csv
import hashlib
import json
import os
import re
import shutil
import signal
import stat
import subprocess

CLASSES = ["panic", "crash", "hang", "wrong_exit", "non_finite", "efficiency", "stray",
           "changed_on_failure", "bad_message"]
LIMIT_S = 10
# Address-space limit of every command (8 GiB): a command that would allocate without bound
# fails (a crash the campaign counts) instead of taking the machine's memory.
ADDRESS_SPACE = 8 << 30
PRLIMIT = shutil.which("prlimit")
NUM_RE = re.compile(r"(?<![A-Za-z_])(nan|NaN|-?inf|-?Infinity)(?![A-Za-z_])")
TMP_RE = re.compile(r"geartherm-(tmp|old)-")
OPTION_ECHOES = {"ambient_c", "initial_temp_c", "frozen_viscosity_c"}


class Proc:
    """The outcome of one command."""

    def __init__(self, rc, out, err, timed_out):
        self.rc, self.out, self.err, self.timed_out = rc, out, err, timed_out


def limited(args):
    """`args` under the address-space limit (and without core files)."""
    if PRLIMIT:
        return [PRLIMIT, f"--as={ADDRESS_SPACE}", "--core=0", "--"] + args
    return args


def run(args, cwd, timeout=LIMIT_S, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, env=None):
    """Run `args` in its own process group; on timeout the whole group is killed."""
    p = subprocess.Popen(limited(args), cwd=cwd, stdin=stdin, stdout=stdout, stderr=stderr,
                         env=env, start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
        return Proc(p.returncode, out or b"", err or b"", False)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, err = p.communicate()
        return Proc(None, out or b"", err or b"", True)


def classify(res, proc, allowed):
    """The process classes of `proc` (panic, crash, hang, wrong exit) into `res`."""
    res["rc"] = "timeout" if proc.timed_out else proc.rc
    if proc.timed_out:
        res["classes"].append("hang")
        return
    err = proc.err.decode(errors="replace")
    if proc.rc == 101 or "panicked at" in err:
        res["classes"].append("panic")
        res["detail"] = err[-300:]
    elif proc.rc < 0:
        res["classes"].append("crash")
        res["detail"] = f"signal {-proc.rc}"
    elif proc.rc not in allowed:
        res["classes"].append("wrong_exit")
        res["detail"] = f"exit {proc.rc}, allowed {sorted(allowed)}: {err[-200:]}"
    if TMP_RE.search(err):
        res["classes"].append("bad_message")
        res["detail"] = err[-300:]


def non_finite_in(text):
    return bool(NUM_RE.search(text))


def json_problems(v, path=""):
    """Paths of nulls that stand for numbers and of efficiencies outside [0, 1]."""
    nf, eff = [], []
    if isinstance(v, dict):
        # A failed row (a bench solver that failed) says so in `failure`; its numbers are null.
        failed = bool(v.get("failure"))
        for k, x in v.items():
            p = f"{path}.{k}"
            if "efficiency" in k and isinstance(x, (int, float)) and not isinstance(x, bool):
                if not (0.0 <= x <= 1.0):
                    eff.append(p)
            # A null option echo (`ambient_c`: the model's own) is "not given", not a number.
            if x is None and not failed and k.endswith(("_w", "_j", "_c", "_s", "_k")) and k not in OPTION_ECHOES:
                nf.append(p)
            if isinstance(x, float) and not (x == x and abs(x) != float("inf")):
                nf.append(p)
            a, b = json_problems(x, p)
            nf += a
            eff += b
    elif isinstance(v, list):
        for i, x in enumerate(v):
            a, b = json_problems(x, f"{path}[{i}]")
            nf += a
            eff += b
    elif isinstance(v, float) and not (v == v and abs(v) != float("inf")):
        nf.append(path)
    return nf, eff


def csv_problems(path):
    """(non-finite, efficiency outside [0, 1], ragged rows) of a written CSV file (quoted
    fields, as the study table's messages, are read as CSV)."""
    nf = eff = False
    with open(path, errors="replace", newline="") as f:
        rows = csv.reader(f)
        header = next(rows, [])
        cols = [i for i, h in enumerate(header) if "efficiency" in h]
        for cells in rows:
            if len(cells) != len(header):
                return nf, eff, True
            nf = nf or any(non_finite_in(c) for c in cells if not c.startswith(("geartherm ", "'")) and " " not in c)
            for i in cols:
                if cells[i]:
                    try:
                        e = float(cells[i])
                        eff = eff or not (0.0 <= e <= 1.0)
                    except ValueError:
                        nf = True
    return nf, eff, False


def check_json_text(res, text, where):
    """A printed or written JSON document: parses, finite, efficiencies in [0, 1]."""
    try:
        doc = json.loads(text)
    except json.JSONDecodeError:
        res["classes"].append("stray" if where == "stdout" else "non_finite")
        res["detail"] = f"{where}: not one JSON document"
        return
    nf, eff = json_problems(doc)
    if nf:
        res["classes"].append("non_finite")
        res["detail"] = f"{where}: {nf[:3]}"
    if eff:
        res["classes"].append("efficiency")
        res["detail"] = f"{where}: {eff[:3]}"


def check_files(res, d):
    """Every CSV, JSON and Markdown file under `d`: finite numbers, efficiencies in [0, 1]."""
    for base, _, files in os.walk(d):
        for n in files:
            fp = os.path.join(base, n)
            if not stat.S_ISREG(os.lstat(fp).st_mode):
                continue
            if n.endswith(".csv"):
                nf, eff, ragged = csv_problems(fp)
                if nf:
                    res["classes"].append("non_finite")
                    res["detail"] = f"{n}: non-finite cell"
                if eff:
                    res["classes"].append("efficiency")
                if ragged:
                    res["classes"].append("stray")
                    res["detail"] = f"{n}: ragged rows"
            elif n.endswith(".json") and not n.startswith("journal"):
                with open(fp, errors="replace") as f:
                    check_json_text(res, f.read(), n)
            elif n.endswith(".md"):
                with open(fp, errors="replace") as f:
                    if non_finite_in(f.read()):
                        res["classes"].append("non_finite")
                        res["detail"] = f"{n}: non-finite number"


def snapshot(d):
    """Every file under `d` (hidden ones too) by relative path: its size and SHA-1."""
    snap = {}
    if not os.path.isdir(d):
        return snap
    for base, dirs, files in os.walk(d):
        for n in files + [x for x in dirs if os.path.islink(os.path.join(base, x))]:
            fp = os.path.join(base, n)
            rel = os.path.relpath(fp, d)
            st = os.lstat(fp)
            if not stat.S_ISREG(st.st_mode):
                # FIFOs, devices and links are not opened (a FIFO would block the campaign).
                snap[rel] = f"mode {st.st_mode:o} -> {os.readlink(fp) if os.path.islink(fp) else ''}"
                continue
            try:
                with open(fp, "rb") as f:
                    snap[rel] = hashlib.sha1(f.read()).hexdigest()
            except OSError:
                snap[rel] = "unreadable"
    return snap


def unchanged(res, before, d):
    """A failed command left `d` byte for byte as it was."""
    after = snapshot(d)
    if after != before:
        changed = sorted(set(after) ^ set(before)) or [k for k in after if after[k] != before.get(k)]
        res["classes"].append("changed_on_failure")
        res["detail"] = f"{d}: {changed[:5]}"


def stray_in(res, d, allowed):
    """Anything in `d` besides `allowed` (names) is stray."""
    extra = sorted(set(os.listdir(d)) - set(allowed)) if os.path.isdir(d) else []
    if extra:
        res["classes"].append("stray")
        res["detail"] = f"stray in {os.path.basename(d)}: {extra[:5]}"


def new_result(case):
    return {"id": case["id"], "family": case["family"], "cmd": case.get("label", ""), "classes": []}
