"""Smoke tests of the three extra figures on toy data (no theory / numerics needed)."""
import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from safebasins import erosion, fourier_compare, phase_invariant, plotting_extras  # noqa: E402

from test_erosion_plumbing import _escape_chart, toy  # noqa: E402,F401

Q = np.linspace(-1, 1, 31)
P = np.linspace(-0.75, 0.75, 25)


def test_three_figures(toy, tmp_path):  # noqa: F811
    F = np.linspace(0, 0.05, 6)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, [0.18, 0.22], Q, P, fourier=["paper", "exact"])
    nu = erosion.erosion_profile_numeric(F, 0.9, np.pi, [0.18, 0.22], Q, P, t_eval=[10, 100], cycles=100)
    fig = plotting_extras.figure_erosion(an, nu, png=tmp_path / "extra_erosion.png")
    assert len(fig.axes) == 3 and (tmp_path / "extra_erosion.png").stat().st_size > 0

    ta = phase_invariant.true_safe_basin_analytic(0.01, 0.9, 0.18, Q, P, n_psi=6)
    tn = phase_invariant.true_safe_basin_numeric(0.01, 0.9, 0.18, Q, P, n_psi=4, t_eval=[50, 100], cycles=100)
    plotting_extras.figure_true_basin(ta, tn, png=tmp_path / "extra_true_basin.png")
    assert (tmp_path / "extra_true_basin.png").stat().st_size > 0

    fc = fourier_compare.fcr_fourier_comparison([0.8, 0.9, 1.0], 0.2)
    io = fourier_compare.iou_fourier_comparison(_escape_chart(Q, P, 0.01, 0.9, np.pi, xi_max=(0.18, 0.22),
                                                              cycles=100))
    plotting_extras.figure_fourier(fc, [io, io], png=tmp_path / "extra_fourier.png")
    assert (tmp_path / "extra_fourier.png").stat().st_size > 0
    fig = plotting_extras.figure_fourier(fc, [io, io])
    assert len(fig.axes) == 3  # one F_cr panel per dataset + RMS bars + IoU bars
    assert "RMS" in fig._suptitle.get_text() and "mean IoU" in fig._suptitle.get_text()


def test_extra_figure_labels(toy):  # noqa: F811
    """Angles as pi fractions in titles; short per-curve labels (only what varies); grouped bar ticks."""
    F = np.linspace(0, 0.05, 3)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, [0.18], Q, P)
    fig = plotting_extras.figure_erosion(an)
    assert r"\pi" in fig._suptitle.get_text() and "3.14" not in fig._suptitle.get_text()

    import xarray as xr
    ds = xr.Dataset(coords={"xi_max": ("curve", [0.242, 0.242]), "xi0": ("curve", [0.0, 0.05]),
                            "gamma0": ("curve", [0.25, 0.25]), "Psi": ("curve", [np.pi, np.pi])})
    labels, const = plotting_extras._curve_labels(ds)
    assert labels == [r"$\xi_{ini}$=0", r"$\xi_{ini}$=0.05"]
    assert r"\pi" in const and "0.242" in const
    fig = plotting_extras.figure_fourier(iou=fourier_compare.iou_fourier_comparison(
        _escape_chart(Q, P, 0.01, 0.9, np.pi, xi_max=(0.18, 0.22), cycles=100)))
    ticks = [t.get_text() for t in fig.axes[0].get_xticklabels()]
    assert ticks == [r"$\xi_{max}$=0.18", r"$\xi_{max}$=0.22"]
