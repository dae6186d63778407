"""safebasins: safe basins for forced escape from a truncated quartic well.

Reproduces Karmi, Kravetc & Gendelman, *Analytic exploration of safe basins in a
benchmark problem of forced escape* (equation numbers in docstrings refer to it).

Subpackages (layers, lowest first: docs/architecture.md)
--------------------------------------------------------
core       argument checks, CF table, provenance (imports nothing of safebasins)
wells      the potentials and their one compiled form
theory     isolated 1:1 resonance: action-angle variables, slow flow, F_cr, basins
numerics   compiled ensemble integration of eq (1), escape charts, bisection, maps
analysis   safe masks, agreement, integrity, erosion, the period map
io         datasets on disk: netCDF, the archive, verification, comparison
plotting, pipeline, explore, cli   figures, the Snakemake side, the explorer, the command line
"""
from safebasins.core import numba_cache
from safebasins.core.version import __version__

__all__ = ["__version__"]

# before any subpackage defines a cached kernel: a read-only install without a writable home
# caches in a private temp directory instead of failing at import
numba_cache.configure()
