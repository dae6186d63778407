"""Structural results of the slow flow do not hang on the last bit.

Two honest runs differ in the last bits of a well's tables (OpenBLAS kernels, numpy's SIMD
paths).  Here those bits are changed on purpose: J perturbed by +-1e-15 relative, the harmonic
shift delta of a symmetric well set to +-4e-16 instead of 0 (what its tables give).  The saddle
branch of critical_forcing at Omega = omega(0) = 1 (where it tends to F = 0 at the IC) and the
boundary curves of a symmetric well (points on the ray gamma = pi, NaN separators where a curve
crosses gamma = +-pi) must come out the same either way."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins.theory import critical_forcing, safe_basin_boundaries
from safebasins.theory.profile import SHIFT_RESOLUTION, resolved_shift
from safebasins.wells import resolve_well

OMEGA = np.array([0.74, 0.86, 1.0])     # 1.0 = omega(0) of the wells with V''(0) = 1


@pytest.mark.parametrize("name", ["pendulum", "cubic", None])
def test_saddle_branch_at_the_linear_frequency(name, monkeypatch):
    w = resolve_well(name)
    xi_max = 0.8 * w.barrier_energy
    runs = []
    for s in (-1.0, 0.0, 1.0):
        J = w.J
        monkeypatch.setattr(w, "J", lambda E, J=J, s=s: J(E) * (1.0 + s * 1e-15))
        runs.append(critical_forcing(OMEGA, xi_max, well=w))
        monkeypatch.undo()
    for ds in runs:
        # F -> 0 at xi_ini is no saddle mechanism: the same NaN in every run
        assert np.isnan(ds["F_SM"].values[-1]) and np.isnan(ds["xi_saddle"].values[-1])
        np.testing.assert_array_equal(np.isnan(ds["F_SM"].values), np.isnan(runs[1]["F_SM"].values))
        np.testing.assert_array_equal(ds["mechanism"].values, runs[1]["mechanism"].values)
        np.testing.assert_allclose(ds["F_cr"].values, runs[1]["F_cr"].values, rtol=1e-12)
    assert np.isfinite(runs[1]["F_cr"].values).all()


def test_saddle_branch_below_resonance_kept():
    """Away from the degenerate point the saddle mechanism is found as before (pendulum,
    xi_max = 1: SM sets F_cr over Omega = 0.74-0.92, its saddle below xi_max)."""
    ds = critical_forcing(np.linspace(0.74, 0.92, 7), 1.0, well="pendulum")
    assert np.isfinite(ds["F_SM"].values).all() and (ds["xi_saddle"].values < 1.0).all()
    assert (ds["F_SM"].values > 0.04).all() and (ds["mechanism"].values == 3).all()


def test_shift_of_a_symmetric_well_is_exactly_zero_asymmetric_kept():
    xi = np.linspace(0.01, 0.9, 50)
    assert (resolved_shift(resolve_well("sech2"), 0.9 * xi) == 0).all()
    d = resolved_shift(resolve_well("cubic"), xi / 6)
    assert (np.abs(d) > SHIFT_RESOLUTION).all()
    np.testing.assert_array_equal(d, resolve_well("cubic").harmonic_shift(xi / 6))


@pytest.mark.parametrize("xi_max", [0.5, 0.9])
def test_symmetric_well_boundaries_do_not_hang_on_delta_noise(xi_max, monkeypatch):
    """sech^2 at F = 0.02, Omega = 1.2728, Psi = pi (the other-wells experiment): delta = +4e-16,
    -4e-16 and the well's own give the same curves, NaN separators in the same places, rays
    exactly 0 or pi."""
    w = resolve_well("sech2")
    runs = []
    for noise in (None, 4e-16, -4e-16):
        if noise is not None:
            shift = w.harmonic_shift
            monkeypatch.setattr(w, "harmonic_shift", lambda E, f=shift, n=noise: f(E) + n)
        runs.append(safe_basin_boundaries(0.02, 1.2728, np.pi, xi_max, well=w, n_points=200))
        monkeypatch.undo()
    ref = runs[0]
    assert set(np.unique(ref["ray"].values)) <= {0.0, np.pi}
    for ds in runs[1:]:
        for v in ("gamma", "xi", "q0_vertex", "p0_vertex", "ray"):
            a, b = ref[v].values, ds[v].values
            assert a.shape == b.shape, v
            np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=v)
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12, err_msg=v)
        assert ds.attrs["saddle_gamma"] == ref.attrs["saddle_gamma"] or (
            np.isnan(ds.attrs["saddle_gamma"]) and np.isnan(ref.attrs["saddle_gamma"]))
