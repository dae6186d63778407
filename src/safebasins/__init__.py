"""safebasins: safe basins for forced escape from a truncated quartic well.

Reproduces Karmi, Kravetc & Gendelman, *Analytic exploration of safe basins in a
benchmark problem of forced escape* (equation numbers in docstrings refer to it).

Subpackages
-----------
theory     isolated 1:1 resonance: action-angle variables, slow flow, F_cr, basins
numerics   compiled ensemble integration of eq (1), escape charts, bisection, maps
"""
from safebasins import _numba_cache

__version__ = "0.1.0"

# before any subpackage defines a cached kernel: a read-only install without a writable home
# caches in a private temp directory instead of failing at import
_numba_cache.configure()
