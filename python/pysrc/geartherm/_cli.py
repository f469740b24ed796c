"""The ``geartherm`` console script: the ``geartherm`` binary the wheel carries
(``geartherm/_bin/geartherm``, built by ``cargo build --release`` from the same sources as the
library when the wheel is built; python/build_backend/geartherm_build.py), run in place of this
process, so its exit codes and its handling of Ctrl-C (``geartherm study`` finishes the running
cases and exits 130; every other command ends at once) are the binary's own.

The binding's library does not contain the command line: clap and indicatif are compiled only
into the binary.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import List, Optional

BIN_DIR = Path(__file__).resolve().parent / "_bin"


def binary() -> Path:
    """The ``geartherm`` binary the wheel carries."""
    return BIN_DIR / ("geartherm.exe" if os.name == "nt" else "geartherm")


def main(argv: Optional[List[str]] = None) -> None:
    args = list(sys.argv if argv is None else argv)
    exe = binary()
    if not exe.is_file():
        sys.stderr.write(
            f"error: {exe}: no geartherm binary in this installation (the wheel carries one: "
            "install with `pip install ./python`)\n"
        )
        sys.exit(3)
    argv0 = ["geartherm"] + args[1:]
    if os.name == "posix":
        sys.stdout.flush()
        sys.stderr.flush()
        os.execv(str(exe), argv0)
    sys.exit(subprocess.call([str(exe)] + args[1:]))


if __name__ == "__main__":
    main()
