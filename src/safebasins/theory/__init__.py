"""Analytic theory: isolated 1:1 resonance (paper Sec. 2).

Modules: action_angle (eqs 4, 7, 13-20), slow_flow (eqs 11, 18, 21), critical (eqs 22-26),
basins (eqs 27-28).
"""
from .action_angle import (H0, q_max_from_xi, J, omega, G, dJ_dxi, dG_dxi, nome,
                           angle_energy, phase_point, initial_condition)

__all__ = ["H0", "q_max_from_xi", "J", "omega", "G", "dJ_dxi", "dG_dxi", "nome",
           "angle_energy", "phase_point", "initial_condition"]
