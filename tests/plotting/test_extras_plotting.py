"""The three extra figures on toy data (no theory / numerics needed): layout, what is drawn
per panel, rendered images that are not blank."""
import matplotlib

matplotlib.use("Agg")

import numpy as np

from safebasins.analysis import erosion, fourier_compare, phase_invariant
from safebasins.plotting import extras as plotting_extras
from tests.analysis.test_extras_plumbing import _escape_chart, toy  # noqa: F401
from tests.plotting.test_plotting import render

Q = np.linspace(-1, 1, 31)
P = np.linspace(-0.75, 0.75, 25)


def test_three_figures(toy, tmp_path):
    F = np.linspace(0, 0.05, 6)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, [0.18, 0.22], Q, P, fourier=["paper", "exact"])
    nu = erosion.erosion_profile_numeric(F, 0.9, np.pi, [0.18, 0.22], Q, P, t_eval=[10, 100], cycles=100)
    fig = plotting_extras.figure_erosion(an, nu)
    assert len(fig.axes) == 3
    for ax in fig.axes:  # per xi_max: two analytic lines (paper, exact) + one marker series per t_eval
        assert len([ln for ln in ax.lines if ln.get_linestyle() in ("-", "--")]) == 2 * 2
        assert len([ln for ln in ax.lines if ln.get_marker() == "o"]) == 2 * 2
    render(fig, tmp_path, "extra_erosion")

    ta = phase_invariant.true_safe_basin_analytic(0.01, 0.9, 0.18, Q, P, n_psi=6)
    tn = phase_invariant.true_safe_basin_numeric(0.01, 0.9, 0.18, Q, P, n_psi=4, t_eval=[50, 100], cycles=100)
    fig = plotting_extras.figure_true_basin(ta, tn)
    assert len(fig.axes) == 3 and "GIM" in fig.axes[0].get_title() and "GIM" in fig.axes[1].get_title()
    assert "Psi" in fig.axes[2].get_ylabel()  # the colour bar of the per-phase outlines
    render(fig, tmp_path, "extra_true_basin")

    fc = fourier_compare.fcr_fourier_comparison([0.8, 0.9, 1.0], 0.2).assign_attrs(source_experiment="fig10")
    io = fourier_compare.iou_fourier_comparison(_escape_chart(Q, P, 0.01, 0.9, np.pi, xi_max=(0.18, 0.22),
                                                              cycles=100)).assign_attrs(source_experiment="fig13")
    fig = plotting_extras.figure_fourier(fc, [io, io])
    assert len(fig.axes) == 3  # one F_cr panel per dataset + RMS bars + IoU bars
    assert "RMS" in fig._suptitle.get_text() and "mean IoU" in fig._suptitle.get_text()
    render(fig, tmp_path, "extra_fourier")


def test_extra_figure_labels(toy):
    """Angles as pi fractions in titles; short per-curve labels (only what varies); grouped bar ticks."""
    F = np.linspace(0, 0.05, 3)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, [0.18], Q, P)
    fig = plotting_extras.figure_erosion(an)
    assert r"\pi" in fig._suptitle.get_text() and "3.14" not in fig._suptitle.get_text()

    import xarray as xr
    ds = xr.Dataset(coords={"xi_max": ("curve", [0.242, 0.242]), "xi_ini": ("curve", [0.0, 0.05]),
                            "gamma_ini": ("curve", [0.25, 0.25]), "Psi": ("curve", [np.pi, np.pi])})
    labels, const = plotting_extras._curve_labels(ds)
    assert labels == [r"$\xi_{ini}$=0", r"$\xi_{ini}$=0.05"]
    assert r"\pi" in const and "0.242" in const
    fig = plotting_extras.figure_fourier(iou=fourier_compare.iou_fourier_comparison(
        _escape_chart(Q, P, 0.01, 0.9, np.pi, xi_max=(0.18, 0.22), cycles=100)).assign_attrs(source_experiment="fig13"))
    ticks = [t.get_text() for t in fig.axes[0].get_xticklabels()]
    assert ticks == [r"$\xi_{max}$=0.18", r"$\xi_{max}$=0.22"]
