"""The analysis layer on three wells: the paper's quartic, the escape equation's cubic
V = q^2/2 - q^3/3 and an asymmetric quartic polynomial with two barriers.

Independent routes: the F = 0 analytic basin against the well's own ``unforced_safe``; the
unforced LIM / IF radii from the orbit curve against the grid distance transform and against a
brute-force search over centres and orbit points from ``phase_point``; analytic against numeric
erosion profiles and masks of the same well (bounds measured on these cases and stated); the
closed-form all-phase integrity against the grid measures of {H0 < xi_true}; the displacement
normalisation against the F = 0 numerics.
"""
import numpy as np
import pytest

from safebasins import wells
from safebasins.analysis import erosion, fourier_compare, integrity, integrity_map, phase_invariant
from safebasins.analysis.agreement import iou
from safebasins.analysis.safe import displacement_energy, q_max_energy, safe_stack
from safebasins.numerics import displacement_bounds, escape_chart

ASYM = [0, 0, 0.5, -0.1, -0.25]     # V = q^2/2 - q^3/10 - q^4/4: barriers at -1.16 (V = 0.41) and 0.86 (0.169)
WELLS = {"quartic": wells.QUARTIC, "cubic": wells.cubic(), "asymmetric": wells.polynomial(ASYM)}


@pytest.fixture(params=list(WELLS))
def well(request):
    return WELLS[request.param]


def _grid(w, xm, nq=41, npp=33):
    """A grid covering S0(xm) of the well with a 5 % margin."""
    lo, hi = (float(np.ravel(t)[0]) for t in w.turning_points(xm))
    pm = 1.05 * np.sqrt(2 * xm)
    return np.linspace(1.05 * lo, 1.05 * hi, nq), np.linspace(-pm, pm, npp)


def _diag(q, p):
    return float(np.hypot(q[1] - q[0], p[1] - p[0]))


def test_asymmetric_polynomial_is_a_valid_well():
    w = WELLS["asymmetric"]
    ql, qr = w.barriers
    assert ql < 0 < qr and np.isfinite([ql, qr]).all()
    assert abs(float(w.dV(ql))) < 1e-12 and abs(float(w.dV(qr))) < 1e-12
    assert w.barrier_energy == pytest.approx(float(w.V(qr))) and float(w.V(ql)) > float(w.V(qr))


# ----------------------------------------------------------------------------- F = 0
def test_unforced_analytic_basin_is_the_wells_unforced_set(well):
    xm = 0.6 * well.barrier_energy
    q, p = _grid(well, xm)
    ds = erosion.erosion_profile_analytic([0.0], 0.9, 0.3, xm, q, p, well=well, keep_masks=True)
    Q, P = np.meshgrid(q, p, indexing="ij")
    np.testing.assert_array_equal(ds["safe"].isel(F=0, xi_max=0).values, well.unforced_safe(Q, P, xm))
    for k in ("GIM", "LIM", "IF"):
        assert float(ds[k].isel(F=0, xi_max=0)) == 1.0
    assert ds.attrs["well"] == well.name and ds.attrs["fourier"] == ("paper" if well.name == "quartic" else "exact")


def test_unforced_radii_against_the_grid_and_a_brute_force_search(well):
    """r_local, r_global of S0 from the orbit curve (integrity.unforced_radii2) vs the grid
    estimator (distance transform, error <= one pixel diagonal) and vs the largest disk found by
    brute force over centres (q_c, p_c) on a grid and orbit points from phase_point."""
    xm = 0.6 * well.barrier_energy
    loc2, glob2 = integrity.unforced_radii2(xm, well)
    q, p = _grid(well, xm, 121, 101)
    m = integrity.integrity_measures(integrity.unforced_safe_mask(q, p, xm, well), q, p, None)
    assert abs(np.sqrt(loc2) - float(m["r_local"])) <= _diag(q, p)
    assert abs(np.sqrt(glob2) - float(m["r_global"])) <= _diag(q, p)
    th = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    bq, bp = (np.asarray(a, float) for a in well.phase_point(th, np.full(th.shape, xm)))
    d_bottom = np.hypot(bq, bp).min()
    assert np.sqrt(loc2) == pytest.approx(d_bottom, rel=1e-5)
    cq, cp = np.meshgrid(np.linspace(q[0], q[-1], 241), np.linspace(-0.05, 0.05, 11), indexing="ij")
    inside = well.unforced_safe(cq, cp, xm).ravel()
    c = np.stack([cq.ravel()[inside], cp.ravel()[inside]], 1)
    best = max(np.hypot(c[i:i + 200, None, 0] - bq, c[i:i + 200, None, 1] - bp).min(axis=1).max()
               for i in range(0, len(c), 200))
    assert np.sqrt(glob2) == pytest.approx(best, abs=2 * (q[-1] - q[0]) / 240)
    assert glob2 >= loc2
    if well.name == "quartic":        # 2 V - q^2 = -q^4/2 <= 0: both exactly 2 xi
        assert (loc2, glob2) == (2 * xm, 2 * xm)
    if well.name == "cubic":          # 2 V - q^2 = -2 q^3/3 is largest at q_minus: r_local = |q_minus|
        assert loc2 == pytest.approx(float(well.turning_points(xm)[0]) ** 2, rel=1e-12)


def test_true_basin_at_F0_is_the_whole_unforced_set(well):
    xm = 0.6 * well.barrier_energy
    q, p = _grid(well, xm, 31, 25)
    ds = phase_invariant.true_safe_basin_analytic(0.0, 0.9, xm, q, p, n_psi=3, n_gamma=64, well=well).isel(xi_max=0)
    assert float(ds["xi_true"]) == pytest.approx(xm, rel=1e-9)
    for k in ("GIM_closed", "LIM_closed", "IF_closed", "GIM_true", "LIM_true", "IF_true"):
        assert float(ds[k]) == pytest.approx(1.0, abs=1e-9), k


# ----------------------------------------------------------------------------- analytic vs numeric
# measured (Omega = 0.9, Psi = pi, xi_max = 0.6 barrier energy, 41 x 33 grid, 300 cycles,
# F = (0, .002, .004, .008, .016) * barrier_energy / 0.25):
#   IoU of the masks, worst over F:  quartic 0.931 (at the largest F), cubic 0.988, asymmetric 0.991
#   |GIM analytic - numeric|, worst: quartic 0.018, cubic 0.0045, asymmetric 0.0033
IOU_BOUND = 0.9
GIM_BOUND = 0.03


def test_erosion_analytic_vs_numeric(well):
    xm = 0.6 * well.barrier_energy
    q, p = _grid(well, xm)
    F = np.array([0, 0.002, 0.004, 0.008, 0.016]) * (well.barrier_energy / 0.25)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, xm, q, p, well=well, keep_masks=True).isel(xi_max=0)
    nu, ch = erosion.erosion_profile_numeric(F, 0.9, np.pi, xm, q, p, cycles=300, well=well, keep_charts=True)
    nu = nu.isel(xi_max=0, t_eval=0)
    assert nu.attrs["well"] == well.name == ch.attrs["well"]
    num = (ch["escape_cycle_energy"] > 300).isel(xi_max=0)
    assert float(iou(an["safe"], num).min()) > IOU_BOUND
    assert float(np.abs(an["GIM"] - nu["GIM"]).max()) < GIM_BOUND
    # the profile erodes with F (strictly, on this F range), from 1 at F = 0
    for prof in (an, nu):
        assert float(prof["GIM"][0]) == 1.0
        assert (prof["GIM"].diff("F") < 0).all()
        assert (prof["LIM"].diff("F") <= 0).all() and (prof["IF"].diff("F") <= 0).all()


def test_phase_invariant_basin_inside_every_phase(well):
    xm = 0.6 * well.barrier_energy
    q, p = _grid(well, xm, 41, 33)
    F = 0.008 * well.barrier_energy / 0.25
    ds = phase_invariant.true_safe_basin_analytic(F, 0.9, xm, q, p, n_psi=4, n_gamma=128, well=well).isel(xi_max=0)
    safe, true, cont = ds["safe"].values, ds["true_safe"].values, ds["true_safe_continuous"].values
    assert bool(ds["contained"]) and not (true & ~safe).any()
    assert not (cont & ~true).any()             # all phases: a subset of the 4-phase intersection
    assert 0 < float(ds["xi_true"]) < xm
    # closed forms vs the grid measures of {H0 < xi_true} (cubic: LIM 0.640 vs 0.661, IF 0.619 vs 0.627)
    assert abs(float(ds["GIM_closed"]) - float(ds["GIM_continuous"])) < 0.02
    r0 = np.sqrt(integrity.unforced_radii2(xm, well)[0])
    for k in ("LIM", "IF"):
        assert abs(float(ds[f"{k}_closed"]) - float(ds[f"{k}_continuous"])) <= 2 * _diag(q, p) / r0, k
    if well.name == "quartic":
        assert float(ds["LIM_closed"]) == float(ds["IF_closed"]) == np.sqrt(float(ds["xi_true"]) / xm)
    b = phase_invariant.phase_boundaries(F, 0.9, xm, [0.0, 1.0], n_points=80, well=well)
    assert np.isfinite(b["boundary_q0"]).sum() > 40


def test_integrity_map_of_a_well():
    w = WELLS["cubic"]
    xm = 0.6 * w.barrier_energy
    q, p = _grid(w, xm, 25, 21)
    ds = integrity_map.integrity_map_analytic([0.85, 0.9], [0.0, 0.005], 0.0, xm, q, p, n_gamma=32, n_xi=16, well=w)
    assert ds.attrs["well"] == "cubic" and ds.attrs["fourier"] == "exact"
    for k in ("GIM", "LIM", "IF", "GIM_true", "LIM_true", "IF_true"):
        np.testing.assert_allclose(ds[k].sel(F=0.0).values, 1.0, atol=1e-9, err_msg=k)
        assert (ds[k].sel(F=0.005) < 1).all(), k
    nu = integrity_map.integrity_map_numeric([0.9], [0.0, 0.005], 0.0, xm, q, p, cycles=100, well=w)
    assert nu.attrs["well"] == "cubic"
    assert float(nu["GIM"].sel(F=0.0).squeeze()) == pytest.approx(1.0, abs=0.05)


# ----------------------------------------------------------------------------- displacement criteria
def test_displacement_energy_against_the_turning_points(well):
    """The orbit of energy displacement_energy(lo, hi) touches one bound and stays inside the
    other (turning points, an independent route); q_max_energy is the symmetric pair."""
    ql, qr = well.barriers
    for lo, hi in ((-0.3, 0.5), (-0.5, 0.3), (max(ql, -0.9), min(qr, 0.7))):
        E = float(displacement_energy(well, lo, hi))
        tl, tr = (float(np.ravel(t)[0]) for t in well.turning_points(E))
        assert (tl == pytest.approx(lo, abs=1e-9) and tr <= hi + 1e-12) or \
               (tr == pytest.approx(hi, abs=1e-9) and tl >= lo - 1e-12), (lo, hi, tl, tr)
    qm = np.linspace(0.05, 0.8, 16)
    np.testing.assert_allclose(q_max_energy(well, qm), displacement_energy(well, -qm, qm), rtol=1e-15)
    if well.name == "quartic":        # the closed form, bit for bit
        np.testing.assert_array_equal(q_max_energy(well, qm), wells.QUARTIC.xi_from_q_max(qm))


def test_displacement_normalisation_at_F0(well):
    """At F = 0 the numeric safe set of a displacement criterion is the unforced set of its
    energy (displacement_energy), so GIM = LIM = IF = 1 up to boundary pixels."""
    xm = 0.6 * well.barrier_energy
    q, p = _grid(well, xm, 31, 25)
    qmax = 0.8 * min(-well.barriers[0], well.barriers[1], -float(well.turning_points(xm)[0]))
    ch = escape_chart(q, p, 0.0, 0.9, 0.0, xi_max=(xm,), q_max=(qmax,), q_bounds=displacement_bounds(xm, well),
                      cycles=20, well=well).assign_attrs(F=0.0)
    Q, P = np.meshgrid(q, p, indexing="ij")
    for crit, energy in (("bounds", xm), ("displacement", float(q_max_energy(well, qmax)))):
        safe, xi_norm = safe_stack(ch, None, crit)
        assert float(xi_norm.squeeze()) == pytest.approx(energy, rel=1e-12)
        assert float(iou(safe.values.squeeze(), well.unforced_safe(Q, P, energy))) > 0.95, crit
        prof = erosion.profile_from_charts(ch, criterion=crit)
        for k in ("GIM", "LIM", "IF"):
            assert float(prof[k].squeeze()) == pytest.approx(1.0, abs=0.08), (crit, k)


# ----------------------------------------------------------------------------- bad input
def test_bad_input_names_the_reason():
    cub, asym = WELLS["cubic"], WELLS["asymmetric"]
    q, p = _grid(cub, 0.1)
    with pytest.raises(ValueError, match="barrier energy of the cubic"):
        erosion.erosion_profile_analytic([0.01], 0.9, 0.0, 0.17, q, p, well=cub)
    with pytest.raises(ValueError, match="barrier energy of the polynomial"):
        phase_invariant.true_safe_basin_analytic(0.01, 0.9, 0.17, q, p, well=asym)
    with pytest.raises(ValueError, match=r"\(0, 1/4\]"):
        erosion.erosion_profile_analytic([0.01], 0.9, 0.0, 0.25 + 1e-9, q, p)
    with pytest.raises(ValueError, match="exact first harmonic"):
        erosion.erosion_profile_analytic([0.01], 0.9, 0.0, 0.1, q, p, fourier="paper", well=cub)
    with pytest.raises(ValueError, match="exact first harmonic"):
        phase_invariant.true_safe_basin_analytic(0.01, 0.9, 0.1, q, p, fourier=["paper", "exact"], well=cub)
    with pytest.raises(ValueError, match="exact first harmonic"):
        integrity_map.integrity_map_analytic([0.9], [0.01], 0.0, 0.1, q, p, fourier="paper", well=cub)
    with pytest.raises(ValueError, match="well must be"):
        erosion.erosion_profile_analytic([0.01], 0.9, 0.0, 0.1, q, p, well=3.5)
    with pytest.raises(ValueError, match="quartic's"):
        fourier_compare.fcr_fourier_comparison([0.9], 0.1, well=cub)
    ch = escape_chart(q[::4], p[::4], 0.01, 0.9, 0.0, xi_max=(0.1,), cycles=5, well=cub)
    with pytest.raises(ValueError, match="quartic's"):
        fourier_compare.iou_fourier_comparison(ch)
    bare = ch.copy()
    bare.attrs = {"cycles": 5}
    with pytest.raises(ValueError, match="names no well"):
        erosion.profile_from_charts(bare)
    with pytest.raises(ValueError, match="inside the barriers"):
        displacement_energy(cub, -0.5, 1.2)
    with pytest.raises(ValueError, match="q_lower < 0 < q_upper"):
        displacement_energy(cub, 0.1, 0.5)
    with pytest.raises(ValueError, match="barrier energy of the cubic"):
        integrity.unforced_radii2(0.2, cub)
    with pytest.raises(ValueError, match="criterion 'bounds'"):
        safe_stack(ch, None, "bounds")
    # "exact" (or nothing) is the only variant of another well, stored as such
    a = erosion.erosion_profile_analytic([0.0], 0.9, 0.0, 0.1, q, p, fourier="exact", well=cub)
    assert a.attrs["fourier"] == "exact"
    b = erosion.erosion_profile_analytic([0.0], 0.9, 0.0, 0.1, q, p, well=wells.QuarticWell("exact"))
    assert b.attrs["fourier"] == "exact" and b.attrs["well"] == "quartic"
