"""safebasins: safe basins for forced escape from a truncated quartic well.

Reproduces Karmi, Kravetc & Gendelman, *Analytic exploration of safe basins in a
benchmark problem of forced escape* (equation numbers in docstrings refer to it).

Subpackages
-----------
theory     isolated 1:1 resonance: action-angle variables, slow flow, F_cr, basins
numerics   compiled ensemble integration of eq (1), escape charts, bisection, maps
"""
__version__ = "0.1.0"
