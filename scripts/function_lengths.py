#!/usr/bin/env python3
"""Function length and nesting of the Rust code outside tests.

    python3 scripts/function_lengths.py [--top N] [--all] [FOLDER ...]

Reads every `fn` with a body in FOLDERs (default: src python/src benches examples), leaving out
test code: folders named `tests`, `#[cfg(test)]` modules (inline or in their own file) and
`#[test]` or `#[cfg(test)]` functions. For each function it measures

- length: lines from the line of `fn` to the closing brace, both included;
- nesting: the deepest indentation of a code line in its body, in levels of four spaces below
  the `fn` line (a statement of the body is at level 1, the body of an `if` in it at level 2; a
  chained call or an argument list broken over lines counts as rustfmt indents it).

Prints the longest and the most deeply nested functions, then every function over the limits
(150 lines, 6 levels). Exit 1 when one of them is not in ALLOWED, or when an entry of ALLOWED no
longer exceeds a limit (the list stays exact). Standard library only; the reading is lexical
(rust_source.py) and relies on rustfmt-formatted code.
"""
import argparse
import os
import re
import sys

from rust_source import FILLER, read_code, rust_files

MAX_LINES = 150
MAX_NESTING = 6
INDENT = 4

# Functions allowed over a limit (none). The check fails on an entry that no longer exceeds a
# limit, so the list stays exact.
# Key: "path::Type::function" (the impl's type, if any); value: what exceeds the limits.
ALLOWED = {}

ITEM = re.compile(r"\b(fn|impl|trait|mod)\b")
FN_NAME = re.compile(r"\bfn\s+(r#)?(\w+)")
TEST_ATTR = re.compile(r"#\[\s*(?:cfg\s*\(\s*test\s*\)|test)\s*\]")


def impl_type(header):
    """The implemented type of an `impl` header: `impl<T> Trait for Type<T>` -> `Type`."""
    rest = header[header.index("impl") + 4 :]
    rest = _drop_generics(rest.strip())
    if re.search(r"\bfor\b", rest):
        rest = re.split(r"\bfor\b", rest, maxsplit=1)[1]
    rest = re.split(r"\bwhere\b", rest)[0]
    m = re.search(r"(\w+)\s*(<.*)?$", rest.strip().split("<")[0].strip())
    return m.group(1) if m else "impl"


def _drop_generics(s):
    """`s` without a leading `<...>` (nested angle brackets)."""
    if not s.startswith("<"):
        return s
    depth = 0
    for i, c in enumerate(s):
        depth += {"<": 1, ">": -1}.get(c, 0)
        if depth == 0:
            return s[i + 1 :]
    return s


def functions(path):
    """(qualified name, first line, last line, nesting) of every non-test function in `path`."""
    code = read_code(path)
    lines = code.split("\n")
    found = []
    # One entry per open brace: (kind, name, start line, indent of the fn line, in test code).
    stack = []
    last = 0  # just past the last `;`, `{` or `}`
    for i, c in enumerate(code):
        if c == ";":
            last = i + 1
        elif c == "{":
            header = code[last:i]
            in_test = bool(stack and stack[-1][4]) or bool(TEST_ATTR.search(header))
            kind, name, start, indent = "block", "", 0, 0
            item = _last_item(header)
            if item == "fn":
                m = list(FN_NAME.finditer(header))[-1]
                offset = last + m.start()
                start = code.count("\n", 0, offset)
                line = lines[start]
                indent = len(line) - len(line.lstrip(" "))
                kind, name = "fn", m.group(2)
            elif item == "impl":
                kind, name = "impl", impl_type(header)
            elif item in ("trait", "mod"):
                m = re.search(item + r"\s+(\w+)", header)
                kind, name = item, m.group(1) if m else item
            stack.append((kind, name, start, indent, in_test))
            last = i + 1
        elif c == "}":
            last = i + 1
            if not stack:
                continue
            kind, name, start, indent, in_test = stack.pop()
            if kind != "fn" or in_test:
                continue
            end = code.count("\n", 0, i)
            owners = [s[1] for s in stack if s[0] in ("impl", "trait", "mod", "fn")]
            qualified = "::".join(owners + [name])
            found.append((qualified, start + 1, end + 1, _nesting(lines[start + 1 : end], indent)))
    return found


def _last_item(header):
    """The item keyword that opens the block after `header`, if the header declares one: the
    header must start (after attributes and visibility) with the item, so that a closure or an
    expression that mentions `fn` is not taken for one."""
    h = re.sub(r"#!?\[[^\]]*\]", " ", header)
    h = re.sub(r"\bpub(\s*\([^)]*\))?", " ", h)
    h = re.sub(r"\b(const|async|unsafe|extern\s*(\"[^\"]*\")?|default)\b", " ", h).strip()
    m = ITEM.match(h)
    return m.group(1) if m else None


def _nesting(body, fn_indent):
    """Deepest indentation of a code line of `body`, in levels below the `fn` line (lines that
    continue a string literal do not count)."""
    deepest = 0
    for line in body:
        if line.strip() and not line.lstrip().startswith(FILLER):
            indent = len(line) - len(line.lstrip(" "))
            deepest = max(deepest, (indent - fn_indent) // INDENT)
    return deepest


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="*", default=["src", "python/src", "benches", "examples"])
    parser.add_argument("--top", type=int, default=10, help="how many of the longest to print")
    parser.add_argument("--all", action="store_true", help="print every function")
    args = parser.parse_args()
    rows = []
    for path in rust_files([f for f in args.folders if os.path.isdir(f)]):
        for name, first, last, nesting in functions(path):
            rows.append((last - first + 1, nesting, f"{path}::{name}", f"{path}:{first}"))
    shown = rows if args.all else sorted(rows, reverse=True)[: args.top]
    print(f"{len(rows)} functions outside tests; the {'' if args.all else 'longest '}lines, nesting:")
    for length, nesting, name, where in sorted(shown, reverse=True):
        print(f"  {length:5} {nesting:3}  {name}  ({where})")
    print("deepest nesting:")
    for length, nesting, name, where in sorted(rows, key=lambda r: (-r[1], -r[0]))[: args.top]:
        print(f"  {length:5} {nesting:3}  {name}  ({where})")
    over = [r for r in rows if r[0] > MAX_LINES or r[1] > MAX_NESTING]
    keys = {r[2] for r in rows}
    failed = False
    print(f"over {MAX_LINES} lines or {MAX_NESTING} levels: {len(over)}")
    for length, nesting, name, where in sorted(over, reverse=True):
        allowed = name in ALLOWED
        failed |= not allowed
        print(f"  {length:5} {nesting:3}  {name}  ({where}){'  [allowed]' if allowed else ''}")
    scanned = [os.path.normpath(f) + os.sep for f in args.folders]
    for name in sorted(n for n in ALLOWED if any(n.startswith(f) for f in scanned)):
        if name not in {r[2] for r in over}:
            failed = True
            gone = "" if name in keys else " (no such function)"
            print(f"  ALLOWED entry within the limits{gone}, remove it: {name}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
