"""Type aliases of the theory's signatures."""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from safebasins.wells.base import Well

__all__ = ["BoolArray", "FloatArray", "WellArg"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
#: what ``wells.resolve_well`` accepts: None (the quartic), a name, a spec mapping or a well
WellArg = Well | str | Mapping[str, Any] | None
