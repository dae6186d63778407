"""Analytic theory: isolated 1:1 resonance (paper Sec. 2).

Modules, each importing only those listed before it: action_angle (eqs 4, 7, 13-20); profile
(the tables of the escape criterion, eqs 18, 21, 25) and slow_flow_grid (an IC grid classified by
it); with damping (docs/damping.md): damped (the damped slow flow and its frames), responses
(fixed points, frequency responses), damped_flow (batch integration with settling certificates),
damped_escape (safe ICs, F_cr), trajectories (one slow trajectory); then the entry points of both
slow flows: slow_flow (eqs 11, 18, 21), critical (eqs 22-26), basins (eqs 27-28).  Under noise
(docs/noise-theory.md): noise_averaging (the averaged diffusion), noise_solver (its backward
equation), noise_escape (escape probabilities, mean first-passage times), noise_quasipotential (the weak-noise
limit: quasi-potential barriers and the Arrhenius law).
"""
from .action_angle import (H0, q_max_from_xi, J, omega, G, dJ_dxi, dG_dxi, nome,
                           angle_energy, phase_point, initial_condition)
from .slow_flow import (first_integral, escapes_on_manifold, slow_flow_escapes,
                        slow_flow_profile, slow_flow_rhs, xi_from_J, saddles)
from .critical import critical_forcing, MECHANISMS
from .basins import safe_basin_boundaries
from .responses import steady_responses
from .trajectories import slow_trajectory
from .damped_escape import slow_flow_outcomes, UndecidedWarning
from .noise_escape import escape_probability, mean_first_passage
from .noise_quasipotential import quasi_potential, QuasiPotential

__all__ = ["H0", "q_max_from_xi", "J", "omega", "G", "dJ_dxi", "dG_dxi", "nome",
           "angle_energy", "phase_point", "initial_condition",
           "first_integral", "escapes_on_manifold", "slow_flow_escapes", "slow_flow_profile",
           "slow_flow_rhs", "xi_from_J", "saddles", "critical_forcing", "MECHANISMS",
           "safe_basin_boundaries", "steady_responses", "slow_trajectory", "slow_flow_outcomes",
           "UndecidedWarning", "escape_probability", "mean_first_passage", "quasi_potential", "QuasiPotential"]
