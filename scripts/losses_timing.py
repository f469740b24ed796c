#!/usr/bin/env python3
"""CPU time (user + system) of one whole `geartherm losses --json` command per bundled model,
mean over N runs (docs/performance.md, "Model-form spread").

Usage: scripts/losses_timing.py [BINARY ...] (default target/release/geartherm); N = 30.
"""
import resource
import subprocess
import sys

MODELS = [
    ("models/at6_lepelletier.toml", "1"),
    ("models/ev_reducer.toml", "D"),
    ("models/fzg_c.toml", "1"),
    ("models/helical_stage.toml", "1"),
    ("models/mm82_wind_gearbox.toml", "run"),
    ("models/pt6_spur_pair.toml", "1"),
]
N = 30


def cpu_ms(binary, model, gear):
    args = [binary, "losses", model, "--gear", gear, "--speed-rpm", "1500", "--torque-nm", "100",
            "--oil-temp-c", "60", "--json"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    for _ in range(N):
        subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    used = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return 1e3 * used / N


binaries = sys.argv[1:] or ["target/release/geartherm"]
print("| model | " + " | ".join(binaries) + " |")
print("|---|" + "---:|" * len(binaries))
for model, gear in MODELS:
    print(f"| {model} | " + " | ".join(f"{cpu_ms(b, model, gear):.2f} ms" for b in binaries) + " |")
