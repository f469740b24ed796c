"""The example notebook (examples/first_hour.ipynb) runs from its first cell to its last, with
its figures, in a fresh kernel of this interpreter."""

from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[2]


def test_the_example_notebook_runs(tmp_path, monkeypatch):
    nb = nbformat.read(ROOT / "examples" / "first_hour.ipynb", as_version=4)
    monkeypatch.setenv("GEARTHERM_ROOT", str(ROOT))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    client = NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    images = [
        o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if "image/png" in o.get("data", {})
    ]
    assert len(images) >= 3, "the run, the Pareto front and the calibration draw a figure each"
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors
    assert (tmp_path / "notebook_calibration" / "calibration.png").exists()
    assert (tmp_path / "notebook_calibration" / "calibrated.toml").exists()
