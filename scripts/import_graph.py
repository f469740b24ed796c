#!/usr/bin/env python3
"""The import graph between the folders of src/ (and python/), its circles, and the arrows that
point up the layer order.

    python3 scripts/import_graph.py [--files]

Reads every Rust file outside tests (rust_source.py: comments, literals and `#[cfg(test)]` items
left out) and every path it names: `use` declarations (with their `{...}` groups) and paths in
code that start with `crate::`, `geartherm::`, `super::` or `self::`, or with the name of one of
the module's own child modules. A path goes to the file of its longest module prefix. A module
reaching into its own child modules (a `mod.rs` calling `child::f`) is the module tree, not an
arrow; the child's use of its parent is one.

Prints
- the folders in the layer order (an arrow = "may use"; never up):
  physics -> model, cycle -> scene -> solve -> reference -> report -> job -> study -> cli, with
  python/ beside cli; src/main.rs belongs to cli; a folder not in the order is listed as unknown;
- every folder arrow (A -> B, with the files of A that use B), and the arrows that point up;
- the circles of folders, and the circles of files (each with the names that tie it);
- with --files, every file arrow.

Exit 1 on a circle (of folders or files) or an arrow up the layer order. Standard library only.
"""
import argparse
import os
import re
import sys
from collections import defaultdict

from rust_source import read_code, rust_files, without_test_code

# Layer of every folder; same number = side by side (neither above the other).
LAYERS = {
    "physics": 0,
    "model": 1,
    "cycle": 1,
    "scene": 2,
    "solve": 3,
    "reference": 4,
    "report": 5,
    "job": 6,
    "study": 7,
    "cli": 8,
    "python": 8,
}

# File circles allowed (none; the check fails on an entry that is no circle any more).
ALLOWED_CIRCLES = {}

ROOTS = ("lib.rs", "main.rs", "mod.rs")
PATH_IN_CODE = re.compile(r"(?<![\w$:])((?:crate|geartherm|super|self)(?:\s*::\s*(?:\w+|\{))+)")
USE = re.compile(r"\buse\s+([^;]+);")
MOD_DECL = re.compile(r"\bmod\s+(\w+)\s*;")


class Crate:
    """One crate: its files and their module paths (tuples of names below the crate root)."""

    def __init__(self, name, root_file):
        self.name = name
        self.module_of = {}  # file -> module path
        self.file_of = {}  # module path -> file
        self._walk(root_file, ())

    def _walk(self, path, module):
        self.module_of[path] = module
        self.file_of[module] = path
        code = without_test_code(read_code(path))
        base = os.path.dirname(path)
        if os.path.basename(path) not in ROOTS:
            base = os.path.join(base, os.path.splitext(os.path.basename(path))[0])
        for m in MOD_DECL.finditer(code):
            for child in (os.path.join(base, m.group(1) + ".rs"), os.path.join(base, m.group(1), "mod.rs")):
                child = os.path.normpath(child)
                if os.path.exists(child):
                    self._walk(child, module + (m.group(1),))
                    break


def expand_use(tree):
    """The paths of a use tree: `a::{b, c::{d, e as f}, self}` -> [a::b, a::c::d, a::c::e, a]."""
    tree = re.sub(r"\s+", "", tree)
    tree = re.sub(r"\bas\w+", "", tree.replace("as", " as")).replace(" ", "")
    return [p for p in _expand(tree) if p]


def _expand(tree):
    if "{" not in tree:
        return [tree.rstrip(":")]
    head, inner = tree.split("{", 1)
    inner = inner[: inner.rindex("}")]
    parts, depth, start = [], 0, 0
    for k, c in enumerate(inner):
        depth += {"{": 1, "}": -1}.get(c, 0)
        if c == "," and depth == 0:
            parts.append(inner[start:k])
            start = k + 1
    parts.append(inner[start:])
    out = []
    for part in filter(None, parts):
        for sub in _expand(part):
            out.append(head.rstrip(":") if sub == "self" else head + sub)
    return out


def resolve(segments, crate, module, lib):
    """(crate, module path) of the file that `segments` (a path read in `module` of `crate`)
    reaches, or None for a path outside the project (std, a dependency)."""
    first, rest = segments[0], segments[1:]
    if first == "crate":
        target, base = crate, ()
    elif first == "geartherm":
        target, base = lib, ()
    elif first in ("super", "self"):
        target, base = crate, module
        while rest is not None and first in ("super", "self"):
            if first == "super":
                base = base[:-1]
            if not rest:
                break
            first, rest = rest[0], rest[1:]
        rest = [first] + list(rest) if first not in ("super", "self") else list(rest)
    elif module + (first,) in crate.file_of:
        target, base, rest = crate, module + (first,), rest
    else:
        return None
    path = tuple(base) + tuple(s for s in rest if s not in ("*",))
    while path and path not in target.file_of:
        path = path[:-1]
    return (target, path)


def file_arrows(crates, lib):
    """{file: {used file: set of names}} over every file of `crates`."""
    arrows = defaultdict(lambda: defaultdict(set))
    for crate in crates:
        for path, module in crate.module_of.items():
            code = without_test_code(read_code(path))
            paths = []
            for m in USE.finditer(code):
                paths += expand_use(m.group(1))
            code_wo_use = USE.sub(" ", code)
            for m in PATH_IN_CODE.finditer(code_wo_use):
                paths.append(re.sub(r"\s+", "", m.group(1)).rstrip(":{"))
            children = {m[-1] for m in crate.file_of if len(m) == len(module) + 1 and m[:-1] == module}
            for m in re.finditer(r"(?<![\w:])(\w+)\s*::\s*\w+", code_wo_use):
                if m.group(1) in children:
                    paths.append(re.sub(r"\s+", "", m.group(0)))
            for p in paths:
                segments = [s for s in p.split("::") if s]
                if not segments:
                    continue
                found = resolve(segments, crate, module, lib)
                if not found:
                    continue
                target, target_module = found
                used = target.file_of[target_module]
                own_child = target is crate and target_module[: len(module)] == module
                if used == path or (own_child and len(target_module) > len(module)):
                    continue
                arrows[path][used].add(segments[-1])
    return arrows


def folder_of(path):
    """The folder of src/ (or `python`) a file belongs to; src/main.rs belongs to cli."""
    parts = os.path.normpath(path).split(os.sep)
    if parts[0] == "python":
        return "python"
    if parts[1] == "main.rs":
        return "cli"
    if parts[1] == "lib.rs":
        return "(crate root)"
    return os.path.splitext(parts[1])[0]


def circles(nodes, edges):
    """Strongly connected components of more than one node (Tarjan, iterative)."""
    index, low, on_stack, stack, out, counter = {}, {}, set(), [], [], [0]
    for start in nodes:
        if start in index:
            continue
        work = [(start, iter(sorted(edges.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, it = work[-1]
            for nxt in it:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]
                    counter[0] += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(edges.get(nxt, ())))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        top = stack.pop()
                        on_stack.discard(top)
                        component.append(top)
                        if top == node:
                            break
                    if len(component) > 1:
                        out.append(sorted(component))
    return sorted(out)


def print_folders(crates, arrows):
    """Print the folders, their arrows and the arrows up the layer order; return the folder
    arrows ({A: {B: files of A that use B}}) and whether an arrow points up."""
    folders = sorted({folder_of(p) for c in crates for p in c.module_of} - {"(crate root)"})
    known = sorted((f for f in folders if f in LAYERS), key=lambda f: (LAYERS[f], f))
    unknown = [f for f in folders if f not in LAYERS]
    print("folders, up the layer order: " + " | ".join(known))
    if unknown:
        print("folders not in the layer order (listed, not judged): " + ", ".join(unknown))
    folder_edges = defaultdict(lambda: defaultdict(set))
    for src, used in arrows.items():
        for dst in used:
            a, b = folder_of(src), folder_of(dst)
            if a != b and "(crate root)" not in (a, b):
                folder_edges[a][b].add(src)
    order = lambda f: (LAYERS.get(f, 99), f)
    print("\nfolder arrows (A -> B: how many files of A use B):")
    for a in sorted(folder_edges, key=order):
        targets = sorted(folder_edges[a], key=order)
        print(f"  {a} -> " + ", ".join(f"{b} ({len(folder_edges[a][b])})" for b in targets))
    print("\narrows up the layer order:")
    up = sorted(
        (a, b)
        for a in folder_edges
        for b in folder_edges[a]
        if a in LAYERS and b in LAYERS and LAYERS[b] > LAYERS[a]
    )
    for a, b in up:
        print(f"  {a} -> {b}: " + ", ".join(sorted(folder_edges[a][b])))
    if not up:
        print("  none")
    return folder_edges, bool(up)


def print_circles(folder_edges, arrows):
    """Print the circles of folders and of files; return whether one is not in ALLOWED_CIRCLES
    or an entry of ALLOWED_CIRCLES is no circle any more."""
    failed = False
    print("\ncircles of folders:")
    folder_circles = circles(sorted(folder_edges), {a: set(b) for a, b in folder_edges.items()})
    for c in folder_circles:
        failed = True
        print("  " + " <-> ".join(c))
    if not folder_circles:
        print("  none")
    print("\ncircles of files (file -> file: the names it takes):")
    file_circles = circles(sorted(arrows), {a: set(b) for a, b in arrows.items()})
    for c in file_circles:
        allowed = frozenset(c) in ALLOWED_CIRCLES
        failed |= not allowed
        folders = ", ".join(sorted({folder_of(f) for f in c}))
        print(f"  {len(c)} files in {folders}{'  [allowed]' if allowed else ''}:")
        for a in c:
            for b in c:
                if b in arrows.get(a, {}):
                    print(f"    {a} -> {b}: {', '.join(sorted(arrows[a][b]))}")
    if not file_circles:
        print("  none")
    for entry in ALLOWED_CIRCLES:
        if sorted(entry) not in file_circles:
            failed = True
            print(f"  ALLOWED_CIRCLES entry is no circle, remove it: {', '.join(sorted(entry))}")
    return failed


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--files", action="store_true", help="print every file arrow too")
    args = parser.parse_args()
    lib = Crate("geartherm", "src/lib.rs")
    crates = [lib, Crate("geartherm (bin)", "src/main.rs")]
    if os.path.exists("python/src/lib.rs"):
        crates.append(Crate("python", "python/src/lib.rs"))
    outside_tests = set(rust_files(["src", "python/src"]))
    for crate in crates:
        for path in [p for p in crate.module_of if p not in outside_tests]:
            module = crate.module_of.pop(path)
            crate.file_of.pop(module, None)
    arrows = file_arrows(crates, lib)
    folder_edges, upward = print_folders(crates, arrows)
    failed = print_circles(folder_edges, arrows) or upward
    if args.files:
        print("\nfile arrows:")
        for a in sorted(arrows):
            for b in sorted(arrows[a]):
                print(f"  {a} -> {b}: {', '.join(sorted(arrows[a][b]))}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
