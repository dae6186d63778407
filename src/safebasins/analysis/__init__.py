"""Analyses of analytic and numeric safe basins.

safe             the one definition ``safe = escape_cycle > t_eval``; safe masks and areas of charts
agreement        IoU, pixel agreement, energy vs displacement criterion counts (Fig 19), escape-probability maps
integrity        GIM, LIM, IF of safe masks
erosion          integrity profiles versus the forcing amplitude
phase_invariant  the safe basin for every forcing phase
fourier_compare  the paper's first harmonic (eq 20) versus the exact one
period_map       rotation numbers, island chains and chaotic orbits of the period map (Fig 18)
confirm          numeric check of the connected parts of an analytic safe basin (Figs 5-9)
melnikov         Melnikov threshold F_M(Omega) of the hilltop saddle: first homoclinic/heteroclinic tangency
basin_measures   basin entropy S_b / S_bb (log 2 criterion), the fractal test, the grid uncertainty exponent
wada             the Wada test of three or more basins (merging method)
basin_labels     labelled basins from escape charts and damped maps; reference_basins: known answers
basin_sides      escape left / safe / escape right of a two-barrier well (the side of the first crossing)
saddle           the forced hilltop saddle's periodic orbit, its manifolds and their first tangency (floquet: shooting)
fatal_shock      the minimal fatal shock of the damped attractors, beside their LIM
continuation     the damped attractors followed across Omega or F (arclength), their basins' GIM/LIM, the Dover cliff
stochastic_integrity  the stochastic safe basin P_escape <= epsilon, its GIM/LIM/IF, erosion against sigma and F
"""
from safebasins.analysis.basin_measures import basin_entropy, fractal_test  # noqa: F401
from safebasins.analysis.wada import wada_test  # noqa: F401
from safebasins.analysis.melnikov import melnikov_curve, melnikov_threshold  # noqa: F401
from safebasins.analysis.saddle import hilltop_orbit, manifold_tangency, saddle_manifolds  # noqa: F401
from safebasins.analysis.fatal_shock import minimal_fatal_shock  # noqa: F401
from safebasins.analysis.continuation import continue_attractors  # noqa: F401
from safebasins.analysis.stochastic_integrity import stochastic_erosion, stochastic_safe_basin  # noqa: F401
from safebasins.analysis.stochastic_integrity import stochastic_erosion_theory  # noqa: F401
