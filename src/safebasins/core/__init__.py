"""The dependency-free core: what every other layer uses, importing nothing of safebasins.

checks       argument checks (a ValueError naming the argument)
cf           the one CF table of units and long names; CF global texts
provenance   provenance attributes of API results, the git commit of the source tree
stacking     datasets stacked along a new dimension (variable-length parts padded)
version      the package version (``safebasins.__version__``)
numba_cache  where numba caches the compiled kernels of an installed package
numba_target how numba compiles the kernels: vector width (512 bits with AVX-512), loop interleave count
statistics   the Wilson interval of escape counts; what a number of paths certifies
settling     how many map iterations settle damped transients (analyses and cost estimates)
averaged_theory  the averaged noise theory's solver defaults, smallest grid and horizon (theory, schemas, CLI)
noise_variates   the names of the noise variates' laws (numerics, schemas, CLI)

Layers (docs/architecture.md): core -> wells -> numerics | theory -> analysis -> io ->
plotting | pipeline | explore -> cli; a layer imports only layers below it.
"""
