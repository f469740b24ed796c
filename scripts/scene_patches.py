#!/usr/bin/env python3
"""Structure check: nothing outside the compile step (src/scene/) assigns into a compiled
scene. The scene is compiled for its scenario (states, ambient, frozen viscosity, what is
recorded: scene::Needs); a job, solver, test or benchmark that writes a field of a Scene (or of
its thermal or loss part) after the compile is reported with file and line.

Every field of a Scene is private to src/scene/ (the compiler refuses a write from elsewhere);
`losses` and `thermal` are read through `Scene::losses()` and `Scene::thermal()`, which return
shared references. This check finds what would still be a patch if a field were opened again: a
statement that assigns through a scene variable (a name containing `scene` or `sc`, or any name
the file binds to a `Scene`: `let x: Scene`, `let x = Scene::compile…`, a parameter
`x: &mut Scene`), a mutable borrow of a scene part (`&mut x.thermal`), or
`std::mem::{swap, replace, take}` on one, and any call of `set_boundary_fixed`.

Run from the repository root: python3 scripts/scene_patches.py (exit 1 on any finding);
`--self-test` checks the patterns on written examples.
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
# Names a file binds to a compiled scene.
BINDING = re.compile(
    r"\blet\s+(?:mut\s+)?(\w+)\s*(?::\s*&?\s*(?:mut\s+)?Scene\b|=\s*(?:\w+::)*Scene::compile)"
    r"|\b(\w+)\s*:\s*&\s*mut\s+Scene\b"
)


def scene_names(text: str):
    """The names bound to a Scene in `text` (see the module's docstring)."""
    names = set()
    for m in BINDING.finditer(text):
        names.add(m.group(1) or m.group(2))
    return names


def patterns(names):
    """Assignment and mutable-borrow patterns for the scene variables of one file."""
    var = r"(?:\w*(?:scene|sc)\w*" + "".join("|" + re.escape(n) for n in sorted(names)) + r")"
    part = var + r"\s*\.\s*(?:" + FIELDS + r")\b"
    assign = re.compile(r"^\s*" + part + r"[\w.\[\]() ]*?\s*(=|\+=|-=|\*=|/=)(?!=)")
    borrow = re.compile(r"&\s*mut\s+(?<![\w.])" + part + r"|\bmem::(?:swap|replace|take)\s*\(\s*&\s*mut\s+" + part)
    return assign, borrow


def line_findings(text: str):
    """(line number, line) of every write into a compiled scene in `text`."""
    assign, borrow = patterns(scene_names(text))
    for k, line in enumerate(text.splitlines(), 1):
        code = line.split("//", 1)[0]
        if ASSIGN.search(code) or assign.search(code) or borrow.search(code) or CALL.search(code):
            yield k, line


def findings(root: pathlib.Path):
    for top in ("src", "tests", "benches", "examples", "python/src"):
        for f in sorted((root / top).rglob("*.rs")):
            rel = f.relative_to(root).as_posix()
            if rel.startswith("src/scene/"):
                continue
            for k, line in line_findings(f.read_text(encoding="utf-8")):
                yield f"{rel}:{k}: {line.strip()}"


SELF_TEST = [
    ("let mut s = Scene::compile(&gb)?;\ns.thermal.ambient = 1.0;", 1),
    ("fn f(x: &mut Scene) {\n    x.losses.items.clear();\n    x.losses = other;\n}", 1),
    ("let t = &mut scene.thermal;", 1),
    ("std::mem::swap(&mut sc.losses, &mut l);", 1),
    ("scene.thermal.names[0] = n;", 1),
    ("let n = scene.thermal.names.len();\nlet m = &model.thermal;", 0),
    ("let mut gb = model;\ngb.thermal.ambient_c = 3.0;", 0),
    ("if scene.thermal.oil == 2 {}", 0),
    ("let n = scene.thermal().names.len();\nlet it = &scene.losses().items[0];", 0),
]


def self_test() -> int:
    bad = 0
    for text, want in SELF_TEST:
        got = len(list(line_findings(text)))
        if got != want:
            print(f"self-test: {want} finding(s) expected, {got} found in: {text!r}")
            bad += 1
    print(f"scene_patches self-test: {len(SELF_TEST) - bad} of {len(SELF_TEST)} examples as expected")
    return 1 if bad else 0


def main() -> int:
    if "--self-test" in sys.argv[1:]:
        return self_test()
    root = pathlib.Path(__file__).resolve().parents[1]
    found = list(findings(root))
    for x in found:
        print(f"scene patched after its compile: {x}")
    print(f"scene_patches: {len(found)} assignment(s) into a compiled scene outside src/scene/")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
