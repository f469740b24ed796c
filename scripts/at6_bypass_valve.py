#!/usr/bin/env python3
"""AT6: the ATF cooler behind a thermostatic bypass valve (`[[thermal.controls]]` valve) against
the bundled model's smooth thermostat on the same two-way exchanger.

Builds the variant (validation/at6_bypass_valve/atf_bypass_valve.toml in place of the
`atf_cooler` block of models/at6_lepelletier.toml), runs both through `geartherm run` on the
WLTC from the model's start (23 °C) and from a warm start (--initial-temp-c 80, where the valve
throttles), and prints the energy per source, the ATF (sump) maximum and final temperature, the
heat the exchanger moved and the energy balance, as the table of docs/validation.md.

Run from the repository root after `cargo build --release`:
    python3 scripts/at6_bypass_valve.py
"""

import json
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
BIN = ROOT / "target" / "release" / "geartherm"


def variant_text() -> str:
    base = (ROOT / "models" / "at6_lepelletier.toml").read_text(encoding="utf-8")
    block = (ROOT / "validation" / "at6_bypass_valve" / "atf_bypass_valve.toml").read_text(encoding="utf-8")
    # The cooler block: from its header to the blank line after `thermostat = ...`.
    pat = re.compile(r"\[\[thermal\.coolers\]\]\nname = \"atf_cooler\"\n.*?thermostat = \{[^\n]*\}\n", re.S)
    if len(pat.findall(base)) != 1:
        sys.exit("the atf_cooler block of models/at6_lepelletier.toml was not found once")
    return pat.sub(lambda _: block, base)


def run(model: pathlib.Path, out: pathlib.Path, extra: list[str]) -> dict:
    cmd = [str(BIN), "run", str(model), "--cycle", "wltc", "--out", str(out), "--quiet", *extra]
    subprocess.run(cmd, check=True, capture_output=True)
    return json.loads((out / "summary.json").read_text(encoding="utf-8"))


def row(label: str, s: dict) -> str:
    by = s["energy_lost_j"]
    sump = s["temperatures_c"]["sump"]
    ctl = "; ".join(
        f"{c['name']}: mean share {c['duty_cycle']:.4f}, {c['switches']} switches, {c['energy_j'] / 1e3:.1f} kJ"
        for c in s.get("controls", [])
    )
    sources = ", ".join(f"{k} {v / 1e3:.2f}" for k, v in by.items() if v != 0.0 or k == "total")
    return (
        f"| {label} | {sources} | {sump['max']:.3f} | {sump['final']:.3f} | "
        f"{s['energy_balance_relative']:.1e} | {ctl or '–'} |"
    )


def main() -> int:
    with tempfile.TemporaryDirectory() as d:
        d = pathlib.Path(d)
        var = d / "at6_bypass_valve.toml"
        var.write_text(variant_text(), encoding="utf-8")
        base = ROOT / "models" / "at6_lepelletier.toml"
        print("| run | energy per source, kJ | ATF max, °C | ATF final, °C | balance | controller |")
        print("|---|---|---|---|---|---|")
        for start, extra in [("23 °C start", []), ("80 °C start", ["--initial-temp-c", "80"])]:
            for label, model in [("thermostat (bundled)", base), ("bypass valve", var)]:
                s = run(model, d / f"{label}{start}".replace(" ", "_"), extra)
                print(row(f"{label}, WLTC, {start}", s))
    return 0


if __name__ == "__main__":
    sys.exit(main())
