"""The worked example of docs/python.md runs as written (fewer study cases)."""

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_the_worked_example_of_the_python_docs_runs(tmp_path):
    import matplotlib  # noqa: F401 (the extra the test needs)
    text = (ROOT / "docs" / "python.md").read_text()
    block = text.split("<!-- worked-example -->", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    block = block.replace("CASES = 40", "CASES = 8")
    block = block.replace('"models/at6_lepelletier.toml"', repr(str(ROOT / "models" / "at6_lepelletier.toml")))
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(block, "docs/python.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert (tmp_path / "pareto.png").stat().st_size > 10_000
    assert (tmp_path / "study" / "study.parquet").exists()
