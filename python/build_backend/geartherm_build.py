"""PEP 517 build backend of the geartherm wheel: maturin's, after one cargo build.

The wheel's extension module (`geartherm._native`, the `geartherm-python` crate) links the
geartherm library without its command line (no clap, no indicatif). Two programs built from the
same sources go into the wheel as package data, in `geartherm/_bin/`:

- `geartherm`: the command-line binary, which the `geartherm` console script runs
  (`geartherm/_cli.py`);
- `libgeartherm_fmu.so`: the FMU runtime library (the `geartherm-fmu` crate) that
  `Model.to_fmu` and `geartherm fmu` put into an FMU (the binary finds it beside itself).

Both come from one `cargo build --release` of the workspace in the workspace's target
directory (`$CARGO_TARGET_DIR` when set), the build `cargo build --release` does, so either
build reuses the other's artifacts. Then maturin builds the extension module and the wheel.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import maturin

HERE = Path(__file__).resolve().parent
PYTHON_DIR = HERE.parent
WORKSPACE = PYTHON_DIR.parent
BIN_DIR = PYTHON_DIR / "pysrc" / "geartherm" / "_bin"


def _artifacts():
    """(built file, name in the package) of each bundled program on this platform."""
    if sys.platform == "win32":
        return [("geartherm.exe", "geartherm.exe"), ("geartherm_fmu.dll", "geartherm_fmu.dll")]
    if sys.platform == "darwin":
        return [("geartherm", "geartherm"), ("libgeartherm_fmu.dylib", "libgeartherm_fmu.dylib")]
    return [("geartherm", "geartherm"), ("libgeartherm_fmu.so", "libgeartherm_fmu.so")]


def _target_dir():
    out = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps", "--offline"],
        cwd=WORKSPACE,
        check=True,
        stdout=subprocess.PIPE,
    ).stdout
    return Path(json.loads(out)["target_directory"])


def _bundle():
    """Build the binary and the FMU runtime and copy them into the package."""
    cmd = ["cargo", "build", "--release", "-p", "geartherm", "--bin", "geartherm", "-p", "geartherm-fmu", "--lib"]
    # Cargo's progress goes to stderr, which pip shows with `-v`.
    subprocess.run(cmd, cwd=WORKSPACE, check=True, stdout=sys.stderr)
    release = _target_dir() / "release"
    BIN_DIR.mkdir(exist_ok=True)
    for built, name in _artifacts():
        dest = BIN_DIR / name
        tmp = dest.with_suffix(dest.suffix + ".tmp")
        shutil.copy2(release / built, tmp)
        os.replace(tmp, dest)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    _bundle()
    return maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    _bundle()
    return maturin.build_editable(wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory, config_settings=None):
    return maturin.build_sdist(sdist_directory, config_settings)


get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
get_requires_for_build_sdist = maturin.get_requires_for_build_sdist
prepare_metadata_for_build_wheel = maturin.prepare_metadata_for_build_wheel
# Optional hooks, only where this maturin has them.
for _hook in ("get_requires_for_build_editable", "prepare_metadata_for_build_editable"):
    if hasattr(maturin, _hook):
        globals()[_hook] = getattr(maturin, _hook)
