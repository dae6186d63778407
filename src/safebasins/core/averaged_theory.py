"""The averaged noise theory's solver settings (safebasins.theory.escape_probability,
docs/noise-theory.md): the defaults of its polar grid and time march, the smallest grid it accepts
and its horizon.  Shared by the theory, the analyses that run it, the pipeline's kind schemas and
the command line, which declare their options without importing the theory."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["CELLS", "MIN_CELLS", "STEPS_PER_CYCLE", "check_cells", "theory_cycles"]

#: cells ``(n_gamma, n_J)`` of the polar grid
CELLS = (128, 160)
#: the smallest number of cells per axis of the polar grid
MIN_CELLS = 8
#: time steps per forcing cycle of the march
STEPS_PER_CYCLE = 8


def check_cells(cells: Any) -> tuple[int, int]:
    """``cells`` as ``(n_gamma, n_J)``: a pair of integers >= :data:`MIN_CELLS` (else a ValueError
    naming ``cells``)."""
    if (not isinstance(cells, tuple) or len(cells) != 2
            or any(isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < MIN_CELLS for c in cells)):
        raise ValueError(f"cells must be a pair of integers >= {MIN_CELLS} (n_gamma, n_J), got {cells!r}")
    return int(cells[0]), int(cells[1])


def theory_cycles(t_eval: npt.ArrayLike) -> int:
    """The theory's horizon in forcing cycles: the largest t_eval rounded up, at least 1."""
    return max(1, math.ceil(float(np.max(t_eval))))
