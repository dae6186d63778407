"""Type aliases of the theory's signatures."""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from safebasins.wells.base import WellLike

__all__ = ["BoolArray", "FloatArray", "WellArg"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
#: what ``wells.resolve_well`` accepts (one home: wells.base.WellLike)
WellArg = WellLike
