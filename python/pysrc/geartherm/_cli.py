"""The ``geartherm`` console script: the command line of the compiled library (the same code as
the ``geartherm`` binary that ``cargo build --release`` makes), run in this process.

SIGINT gets its default action first, as in the binary: ``geartherm study`` installs its own
handler (no new case starts, the running ones finish and are journaled; exit 130), every other
command ends at once.
"""

from __future__ import annotations

import signal
import sys
from typing import List, Optional


def main(argv: Optional[List[str]] = None) -> None:
    from . import _native

    signal.signal(signal.SIGINT, signal.SIG_DFL)
    args = list(sys.argv if argv is None else argv)
    args[0] = "geartherm"
    sys.exit(_native.cli(args))


if __name__ == "__main__":
    main()
