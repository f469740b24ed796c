"""The docs' Python examples type-check with ``mypy --strict`` against the installed package
(its ``py.typed`` and stubs): the signatures they use carry no ``Any``."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "docs" / "python.md", ROOT / "README.md"]


def _blocks():
    for doc in DOCS:
        for k, block in enumerate(re.findall(r"```python\n(.*?)```", doc.read_text(), re.S)):
            yield f"{doc.stem}_{k}", block


def test_the_docs_examples_pass_mypy_strict(tmp_path):
    files = []
    for name, block in _blocks():
        f = tmp_path / f"{name.replace('-', '_').replace('.', '_')}.py"
        f.write_text(block)
        files.append(str(f))
    assert len(files) >= 5, files
    p = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict",
         # distributed's own LocalCluster and Client have no annotations (not geartherm's).
         "--untyped-calls-exclude", "distributed", "--no-incremental", "--cache-dir", str(tmp_path / ".mypy"), *files],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    assert "Success" in p.stdout


def test_the_public_signatures_have_no_any():
    import inspect
    import typing

    import geartherm

    def hints(f):
        return typing.get_type_hints(f, globalns=vars(sys.modules[f.__module__]))

    seen = 0
    for name in geartherm.__all__:
        obj = getattr(geartherm, name)
        funcs = [obj] if inspect.isfunction(obj) else [m for _, m in inspect.getmembers(obj, inspect.isfunction) if not _.startswith("_")] if inspect.isclass(obj) else []
        for f in funcs:
            if f.__module__.startswith("geartherm"):
                text = str(inspect.signature(f))
                assert "Any" not in text, f"{name}.{f.__name__}{text}"
                seen += 1
    assert seen > 20
