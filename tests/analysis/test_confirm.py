"""Numeric confirmation of the connected parts of an analytic basin (analysis.confirm) and the
analytic per-phase boundary curves (analysis.phase_invariant.phase_boundaries)."""
import numpy as np
import pytest

from safebasins.analysis.confirm import confirm_regions
from safebasins.analysis.phase_invariant import phase_boundaries
from safebasins.theory import angle_energy, first_integral


def test_regions_are_labelled_by_size_with_their_kept_fraction():
    safe = np.zeros((12, 12), bool)
    safe[1:6, 1:6] = True          # 25 px, 5 of them escape numerically
    safe[8:10, 8:11] = True        # 6 px, all escape
    safe[11, 0] = True             # 1 px, kept
    ec = np.full(safe.shape, np.inf)
    ec[1, 1:6] = 3.0
    ec[8:10, 8:11] = 0.5
    lab, size, frac = confirm_regions(safe, ec, 10)
    assert size.tolist() == [25, 6, 1]
    np.testing.assert_allclose(frac, [20 / 25, 0.0, 1.0])
    assert (lab[~safe] == 0).all() and lab[2, 2] == 1 and lab[8, 8] == 2 and lab[11, 0] == 3
    # escape after t_eval counts as kept
    assert confirm_regions(safe, np.where(safe, 50.0, np.nan), 10)[2].tolist() == [1.0, 1.0, 1.0]
    with pytest.raises(ValueError, match="one shape"):
        confirm_regions(safe, ec[:5], 10)


def test_phase_boundaries_are_level_curves_of_the_rotated_slow_flow():
    """Independent route: every vertex of the phase-Psi curves maps back (angle_energy) to the
    resonance manifold at gamma = theta - Psi on one level of C, the same level for Psi = 0."""
    F, Om, xi_max, psis = 0.01, 0.9, 0.18, [0.0, 1.0, 2.5]
    b = phase_boundaries(F, Om, xi_max, psis, n_points=200)
    assert b["boundary_q0"].dims == ("Psi", "xi_max", "vertex")
    levels = []
    for k, ps in enumerate(psis):
        q = b["boundary_q0"].isel(Psi=k, xi_max=0).values
        p = b["boundary_p0"].isel(Psi=k, xi_max=0).values
        c = b["boundary_curve"].isel(Psi=k, xi_max=0).values
        per = []
        for ci in np.unique(c[c >= 0]):
            ok = (c == ci) & np.isfinite(q)
            theta, xi = angle_energy(q[ok], p[ok])
            C = first_integral(np.asarray(theta) - ps, np.asarray(xi), F, Om)
            assert np.ptp(C) < 1e-6
            per.append(float(np.mean(C)))
        levels.append(sorted(per))
    np.testing.assert_allclose(levels[1], levels[0], atol=1e-6)
    np.testing.assert_allclose(levels[2], levels[0], atol=1e-6)
    # the curves themselves move with the phase
    assert np.nanmax(np.abs(b["boundary_q0"].isel(Psi=1) - b["boundary_q0"].isel(Psi=0))) > 0.05
