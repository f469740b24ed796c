"""Reading Rust sources for the structure checks (scripts/function_lengths.py,
scripts/import_graph.py): the code of a file with its comments and the insides of its string and
character literals blanked out (line and column positions kept), and the list of files that are
test code (under a `tests/` folder, or a module file declared behind `#[cfg(test)]`).

Standard library only. The reading is lexical (no Rust parser): it relies on rustfmt-formatted
code, which the CI checks first.
"""
import os
import re

# What the contents of a literal become in the blanked code: no bracket, quote or space.
FILLER = "~"


def blank(text):
    """`text` with comments replaced by spaces and the contents of string, byte-string,
    raw-string and character literals by `FILLER` (newlines kept, so line numbers and columns
    stay; a line that starts inside a string starts with `FILLER` after its spaces). Lifetimes
    (`'a`) are kept as code. Block comments nest, as in Rust."""
    out = []
    i, n = 0, len(text)

    def keep_newlines(s, fill=FILLER):
        return "".join(c if c == "\n" else fill for c in s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(keep_newlines(text[i:j], " "))
            i = j
        elif c in "rb" and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'(br|r|b)(#*)"', text[i:])
            if m and (m.group(1) != "b" or m.group(2) == ""):
                if m.group(1) == "b":
                    j = _end_of_quoted(text, i + 2)
                else:
                    close = '"' + m.group(2)
                    j = text.find(close, i + m.end())
                    j = n if j < 0 else j + len(close)
                out.append(text[i : i + m.end()] + keep_newlines(text[i + m.end() : j - 1]) + '"')
                i = j
            elif text.startswith("b'", i):
                j = _end_of_char(text, i + 1)
                out.append("b'" + FILLER * (j - i - 3) + "'")
                i = j
            else:
                out.append(c)
                i += 1
        elif c == '"':
            j = _end_of_quoted(text, i + 1)
            out.append('"' + keep_newlines(text[i + 1 : j - 1]) + '"')
            i = j
        elif c == "'":
            j = _end_of_char(text, i)
            if j > 0:
                out.append("'" + FILLER * (j - i - 2) + "'")
                i = j
            else:  # a lifetime or a label
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _end_of_quoted(text, i):
    """Index just past the closing `"` of a string whose contents start at `i`."""
    n = len(text)
    while i < n:
        if text[i] == "\\":
            i += 2
        elif text[i] == '"':
            return i + 1
        else:
            i += 1
    return n


def _end_of_char(text, i):
    """Index just past a character literal starting with the `'` at `i`, or -1 when the quote
    opens a lifetime or a label."""
    if text.startswith("\\", i + 1):
        j = text.find("'", i + 3)
        return -1 if j < 0 else j + 1
    if i + 2 < len(text) and text[i + 2] == "'" and text[i + 1] != "\n":
        return i + 3
    return -1


def module_file(declaring, name):
    """The file of module `name` declared (`mod name;`) in the file `declaring`."""
    folder = os.path.dirname(declaring)
    stem = os.path.splitext(os.path.basename(declaring))[0]
    if stem not in ("mod", "lib", "main"):
        folder = os.path.join(folder, stem)
    for candidate in (os.path.join(folder, name + ".rs"), os.path.join(folder, name, "mod.rs")):
        if os.path.exists(candidate):
            return os.path.normpath(candidate)
    return None


CFG_TEST_MOD_FILE = re.compile(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;")


def rust_files(roots):
    """Every `.rs` file under the folders `roots`, sorted, with the test files left out: those
    under a folder named `tests`, and module files declared behind `#[cfg(test)]` (with the
    files of their own submodules)."""
    files = []
    for root in roots:
        for folder, dirs, names in os.walk(root):
            dirs[:] = sorted(d for d in dirs if d != "tests" and not d.startswith("."))
            files += [os.path.normpath(os.path.join(folder, f)) for f in names if f.endswith(".rs")]
    files.sort()
    test_files = set()
    for path in files:
        with open(path, encoding="utf-8") as f:
            code = blank(f.read())
        for m in CFG_TEST_MOD_FILE.finditer(code):
            found = module_file(path, m.group(1))
            if found:
                test_files.add(found)
    test_folders = [
        os.path.dirname(t) if os.path.basename(t) == "mod.rs" else os.path.splitext(t)[0]
        for t in test_files
    ]
    kept = []
    for path in files:
        inside_test = path in test_files or any(path.startswith(d + os.sep) for d in test_folders)
        if not inside_test:
            kept.append(path)
    return kept


def read_code(path):
    """The blanked code of the file at `path` (see `blank`)."""
    with open(path, encoding="utf-8") as f:
        return blank(f.read())


TEST_ATTR = re.compile(r"#\[\s*(?:cfg\s*\(\s*test\s*\)|test)\s*\]")


def without_test_code(code):
    """Blanked `code` (see `blank`) with every item behind `#[cfg(test)]` or `#[test]` (a test
    module, function or import) replaced by spaces, newlines kept."""
    out = list(code)
    pos = 0
    while True:
        m = TEST_ATTR.search(code, pos)
        if not m:
            return "".join(out)
        semi, brace = code.find(";", m.end()), code.find("{", m.end())
        if brace < 0 or 0 <= semi < brace:
            end = len(code) if semi < 0 else semi + 1
        else:
            depth, end = 0, len(code)
            for k in range(brace, len(code)):
                depth += {"{": 1, "}": -1}.get(code[k], 0)
                if depth == 0:
                    end = k + 1
                    break
        for k in range(m.start(), end):
            if out[k] != "\n":
                out[k] = " "
        pos = end
