"""Bad input to the theory API: a ValueError saying which argument and why, never NaN or an
IndexError (cases that used to slip through)."""
import numpy as np
import pytest

from safebasins import theory

CASES = [
    ("theta", lambda: theory.phase_point(np.inf, 0.1)),
    ("theta", lambda: theory.phase_point(np.nan, 0.1)),
    ("Psi", lambda: theory.initial_condition(0.1, 0.0, np.inf)),
    ("gamma_ini", lambda: theory.initial_condition(0.1, np.inf, 0.0)),
    ("Omega", lambda: theory.critical_forcing([np.inf], 0.15)),
    ("F", lambda: theory.slow_flow_escapes(0.1, 0.1, np.inf, 0.9, 0.0, 0.18)),
    ("Omega", lambda: theory.safe_basin_boundaries(0.01, np.inf, np.pi, 0.18)),
    ("n", lambda: theory.slow_flow_profile(0.01, 0.9, 0.18, n=0)),
    ("q", lambda: theory.H0(np.inf, 0.0)),
    ("q", lambda: theory.angle_energy(np.nan, 0.0)),
]


@pytest.mark.parametrize("name,call", CASES, ids=[f"{i}-{c[0]}" for i, c in enumerate(CASES)])
def test_bad_input_names_the_argument(name, call):
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        call()
