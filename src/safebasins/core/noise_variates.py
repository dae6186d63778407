"""The laws of the noise's random variates, by name (docs/noise.md).

Light (no numba): the pipeline's schemas and the command line offer the names without loading
the engine; numerics.noise_kernels numbers them in this order and draws them.

* ``gaussian``: Box-Muller pairs of Philox blocks (the default);
* ``five-point``: 0, +-sqrt 2, +-2 with probabilities 5/8, 1/8, 1/16, the Gaussian's moments
  through the fifth (weak order 2 as well), four random bits each.
"""
from __future__ import annotations

__all__ = ["VARIATES", "DEFAULT_VARIATES"]

VARIATES = ("gaussian", "five-point")
DEFAULT_VARIATES = VARIATES[0]
