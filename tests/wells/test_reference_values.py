"""The polynomial wells the pipeline uses keep their public numbers: barriers, limits, V, J, omega,
period, the first harmonic and its derivatives, turning points, phase points and angles of the
cubic, the quartic by quadrature and an asymmetric quartic, against the values stored from the
code of commit ee37d31 (tests/wells/reference_values.py), on any x86-64 machine.

Why not bit for bit.  Those bits depend on the machine: OpenBLAS picks its kernel by CPU, and the
wells go through LAPACK/BLAS when they are built (``np.roots`` of ``V'`` and ``V - E_b``: the
eigenvalues of the companion matrix; Gauss-Legendre nodes: a symmetric eigenproblem;
Clenshaw-Curtis weights: ``inv`` of a Chebyshev-Vandermonde matrix and a matrix product; the
Chebyshev coefficients of the energy interpolants: ``lstsq``) and when they are evaluated (the
orbit quadratures ``f @ S.T``, ``f @ w``: gemm/gemv).  numpy's own CPU dispatch matters too: on
this Cascade Lake the Haswell kernel with numpy's AVX-512 loops reproduces the stored bits, the
same kernel with numpy's AVX2 loops (an AVX2-only CPU) does not.  The stored file was never
regenerated and needs no regeneration on a new machine.

Where the protection lives now.  (a) Every stored quantity is compared with a tolerance of its
own (reference_values.CHECKS), measured, not guessed: ``python -m tests.wells.reference_values``
runs the wells in separate processes under OPENBLAS_CORETYPE = Haswell (also Zen's), SkylakeX,
Cooperlake, Sandybridge, Nehalem, Core2, Barcelona, Prescott and under Haswell / SkylakeX with
numpy's AVX-512 loops off.  Worst difference from the stored values over those ten (Intel Xeon
Cascade Lake; no quantity uses more than 0.098 of its tolerance):

* barriers, barrier energy, limits, omega0, V, V', turning points, the inputs: 0 ulp (roots of
  ``V'`` are Newton-polished, turning points solved by bracketed Newton, V by Horner's rule);
  tolerance 4 ulp.
* J, omega, period, dJ/dE, |q_1|, arg q_1, q_1: 4.8e-15 relative (quartic q_1, AVX2 loops),
  every energy down to the last float below E_b; tolerance 1e-13 relative.
* d|q_1|/dE, d arg q_1/dE (over the modulus of ``d log q_1/dE``): 7.3e-13 for
  ``E <= 0.999 E_b``, 4.1e-12 down to ``E_b - E = 1e-12 E_b``, up to 4.2e-7 at the last floats
  below E_b, where the interpolant's slope is fitted through a handful of distinct floats;
  tolerance ``1e-11 + 256 eps / sqrt((E_b - E)/E_b)``.
* phase points (q, p over the well's extent and sqrt(2 E_b)): 7.8e-15 for ``E <= 0.999 E_b``,
  6.7e-10 at ``E_b - E = 1e-12 E_b`` (the angle of a point is ill-conditioned there);
  tolerance ``1e-13 + 64 eps / sqrt((E_b - E)/E_b)``.
* angles of points: 9.8e-15 rad (E of the points: 0 ulp); tolerance 1e-13 rad, 4 ulp.
* interpolation_error (the largest trailing Chebyshev coefficient, a number at the noise floor):
  3.1e-5 relative; tolerance 1e-3.

Structure is never a matter of tolerance: shapes, NaN and inf patterns must be equal.

These tolerances still catch a changed quadrature or interpolation (measured, share of the
tolerance in the worst quantity): Chebyshev order 20 -> 18 or 22 per panel (3.2e3, 6.4e3),
Clenshaw-Curtis nodes 20 -> 18 or 24 (6.4e2, 2.4e3), Gauss-Legendre points 12 -> 10 or 14
(8.3e3, 3.1e3), ``n_mean`` 4 -> 6 (9.0e3), the panel length 1.5 -> 1 (7.5e2), the bottom /
separatrix split at 0.45 E_b (2.6e3), the separatrix panel step 2.5 -> 2 (4.5e3); the largest
changes sit within 1e-8 E_b of the separatrix (period: 4e-11 relative for order 18), in the
bulk they are ~1e-15.  Changes that leave every number within a few ulps pass (interpolation
tol 1e-12 or 3e-14, three bottom panels, another barrier zone: <= 0.5 of the tolerance).
:func:`test_tolerances_catch_a_changed_interpolation` keeps two of those measurements.

(b) Bit for bit, only within one process: a well rebuilt from its spec, or the quartic given as
a coefficient list, gives the same bits as the named factory (:func:`test_same_bits_in_one_process`).
"""
import numpy as np
import pytest

from safebasins.wells import from_spec
from safebasins.wells.interpolation import EnergyInterpolant
from safebasins.wells.orbit_quadrature import OrbitQuadrature
from safebasins.wells.polynomial import polynomial
from tests.wells.reference_values import PATH, WELLS, compute, errors, structure, worst

STORED = dict(np.load(PATH))


@pytest.fixture(scope="module")
def now():
    return compute(STORED)


@pytest.mark.parametrize("key", sorted(STORED))
def test_matches_stored_values(now, key):
    ref = STORED[key]
    assert structure(now[key], ref) is None, (key, structure(now[key], ref))
    err, tol = errors(key, now[key], ref, STORED, now[f"Et/{key.split('/')[0]}"])
    k = np.unravel_index(np.argmax(err / tol), err.shape)
    assert (err <= tol).all(), f"{key}: error {err[k]:.3g} > tolerance {tol[k]:.3g} at {k}"


def test_structure_differences_are_found():
    a = np.array([1.0, np.nan, np.inf])
    assert structure(a, a) is None
    assert "NaN" in structure(np.array([1.0, 2.0, np.inf]), a)
    assert "inf" in structure(np.array([1.0, np.nan, -np.inf]), a)
    assert "shape" in structure(a[:2], a)


@pytest.mark.parametrize("patch", [(EnergyInterpolant, "n", 18), (OrbitQuadrature, "n_nodes", 18)],
                         ids=["chebyshev-order", "clenshaw-curtis-nodes"])
def test_tolerances_catch_a_changed_interpolation(monkeypatch, patch):
    """The quartic built with one integer of its quadrature or interpolation changed is out of
    tolerance: its period near the separatrix moves by ~1e-11 (measured 8e2 and 4e2 times the
    tolerance)."""
    cls, name, value = patch
    monkeypatch.setitem(cls.__init__.__kwdefaults__, name, value)
    quartic = {k: v for k, v in STORED.items() if k.startswith("quartic_polynomial/")}
    res = worst(compute(STORED, wells={"quartic_polynomial": WELLS["quartic_polynomial"]}), quartic)
    assert res["quartic_polynomial/period"][0] > 10, res["quartic_polynomial/period"]
    assert res["quartic_polynomial/barriers"][0] == 0.0


def test_same_bits_in_one_process(now):
    """Within one process the bits are a promise: the spec a dataset records rebuilds the same
    well, and the quartic as a coefficient list is the quartic."""
    for name, rebuilt in [("cubic", from_spec(WELLS["cubic"]().spec())),
                          ("asymmetric", from_spec(WELLS["asymmetric"]().spec())),
                          ("quartic_polynomial", polynomial([0.0, 0.0, 0.5, 0.0, -0.25]))]:
        again = compute(STORED, wells={name: lambda w=rebuilt: w})
        for key, value in again.items():
            assert np.array_equal(value, now[key], equal_nan=True), key
