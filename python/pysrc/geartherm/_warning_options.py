"""``python -W ACTION::geartherm.RangeWarning`` (and ``PYTHONWARNINGS``) for an installed
package.

CPython reads ``-W`` options before ``site`` puts site-packages on ``sys.path``, so a warning
category of an installed package cannot be imported then: CPython prints "Invalid -W option
ignored: invalid module name" and drops the option. The ``geartherm-warnings.pth`` file the
wheel installs runs this module once site-packages is importable (only when an option names
geartherm), and it applies those options again, in their order, ahead of the filters already
set; the filter then holds for the whole process (CPython's notice has already been printed).
"""

from __future__ import annotations

import sys
import warnings


def apply() -> None:
    mine = [o for o in sys.warnoptions if "geartherm" in o]
    if mine:
        warnings._processoptions(mine)  # type: ignore[attr-defined]


apply()
