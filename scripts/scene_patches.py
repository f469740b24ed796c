#!/usr/bin/env python3
"""Structure check: nothing outside the compile step (src/scene/) assigns into a compiled
scene. The scene is compiled for its scenario (states, ambient, frozen viscosity, what is
recorded: scene::Needs); a job, solver, test or benchmark that writes a field of a Scene (or of
its thermal or loss part) after the compile is reported with file and line.

Run from the repository root: python3 scripts/scene_patches.py (exit 1 on any finding).
"""

import pathlib
import re
import sys

# Scene's fields and those of its parts (ThermalScene, LossScene) that a patch would write.
FIELDS = (
    "losses|thermal|skipped|frozen_oil_temp|energy_slot|energies|item_energies|oil_temp_clamp"
)
# A statement that starts with a scene variable's field (`scene.x = …`, `scene_from.thermal.y += …`).
ASSIGN = re.compile(
    r"^\s*\w*(scene|sc)\w*\s*\.\s*(" + FIELDS + r")\b[\w.\[\]() ]*?\s*(=|\+=|-=|\*=|/=)(?!=)"
)
CALL = re.compile(r"\bset_boundary_fixed\s*\(")


def findings(root: pathlib.Path):
    for top in ("src", "tests", "benches", "python/src"):
        for f in sorted((root / top).rglob("*.rs")):
            rel = f.relative_to(root).as_posix()
            if rel.startswith("src/scene/"):
                continue
            for k, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
                code = line.split("//", 1)[0]
                if ASSIGN.search(code) or CALL.search(code):
                    yield f"{rel}:{k}: {line.strip()}"


def main() -> int:
    root = pathlib.Path(__file__).resolve().parents[1]
    found = list(findings(root))
    for x in found:
        print(f"scene patched after its compile: {x}")
    print(f"scene_patches: {len(found)} assignment(s) into a compiled scene outside src/scene/")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
