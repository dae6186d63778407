"""The referee's list on small synthetic datasets: what the legends and captions say
agrees with what is drawn, and the numbers come from the data."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from safebasins.plotting import basins, fcr, integrity_maps
from safebasins.plotting.captions import notes
from tests.plotting.test_plotting import fcr_stack, rm_basin


def test_fig3_names_the_largest_branch_operative():
    ds = fcr_stack(n_curve=1).isel(curve=0)
    fig = fcr.figure_fcr(ds, color_by="mechanism", show_branches=True)
    leg = fig.axes[0].get_legend()
    assert "largest" in leg.get_title().get_text()
    assert not any("minimum" in t.get_text() for t in leg.get_texts())
    text = " ".join(notes(fig))
    assert "F_cr is the largest branch" in text and "Branches below F_cr:" in text
    plt.close(fig)


def test_fcr_comparison_splits_the_error_by_side_and_keeps_the_end_markers():
    ana, num = fcr_stack(), fcr_stack(numeric=True)
    num["F_cr"] = num["F_cr"] * xr.where(num.Omega < 0.7, 0.5, 0.95)  # theory far off on the SM(M) side only
    fig = fcr.figure_fcr_comparison(ana, num, layout="overlay")
    text = " ".join(notes(fig))
    assert "SM side median" in text and "MM side median" in text
    assert "the SM side is worse" in text and "isolated-resonance approximation" in text
    lo, hi = fig.axes[0].get_xlim()
    assert lo < float(ana.Omega.min()) and hi > float(ana.Omega.max())
    plt.close(fig)


def test_rm_window_reaches_above_xi_max_and_keeps_a_cut_part_whole():
    ds = rm_basin()
    G, X = np.meshgrid(ds.gamma_rm.values, ds.xi_rm.values)
    ds["escapes_rm"] = (("xi_rm", "gamma_rm"), ~((np.abs(G) > 0.8 * np.pi) & (X > 0.05) & (X < 0.2)))
    fig = basins.figure_rm_basin(ds)
    left = fig.axes[0]
    lo, hi = left.get_xlim()
    assert lo < -np.pi and hi > np.pi  # the island across gamma = +-pi is drawn whole
    assert left.get_ylim()[1] > ds.attrs["xi_max"]  # the truncation line is not on the frame
    assert any("widened" in n for n in notes(fig))
    plt.close(fig)


def test_numeric_check_hatches_the_escaping_ics():
    ds = rm_basin()
    Q, P = np.meshgrid(ds.q0.values, ds.p0.values, indexing="ij")
    safe = ~ds["escapes"].values
    ds["region"] = (("q0", "p0"), safe.astype(int))
    ds["region_size"] = ("region_index", [int(safe.sum())])
    ec = np.where(safe, np.where(P > 0.2, 5.0, np.inf), np.nan)  # the top of the basin escapes early
    ds["escape_cycle_numeric"] = (("q0", "p0"), ec)
    ds["region_numeric_safe"] = ("region_index", [float(np.isinf(ec[safe]).mean())])
    ds.attrs["check_cycles"] = 20
    fig = basins.figure_rm_basin(ds)
    n_esc = int((safe & (P > 0.2)).sum())
    assert f"In all {n_esc:,} of {int(safe.sum()):,} analytic-safe ICs" in " ".join(notes(fig))
    assert any("numerics escape" in t.get_text() for t in fig.axes[1].get_legend().get_texts())
    plt.close(fig)


def _maps():
    Om, F, t = np.linspace(0.8, 1.0, 4), np.linspace(0, 0.04, 5), np.array([10.0, 20.0])
    O, FF = np.meshgrid(Om, F, indexing="ij")
    g = np.clip(1 - FF / (0.01 + np.abs(O - 0.9)), 0, 1)
    an = xr.Dataset({"GIM": (("Omega", "F"), g), "LIM": (("Omega", "F"), g ** 2),
                     **{k: ("Omega", 0.01 + np.abs(Om - 0.9)) for k in ("F_GIM", "F_LIM")},
                     **{k: ("Omega", 0.005 + np.abs(Om - 0.9)) for k in ("F_GIM_true", "F_LIM_true")}},
                    coords={"Omega": Om, "F": F}, attrs={"xi_max": 0.18, "Psi": np.pi})
    d = -0.15 * g * (1 - g)
    nu = xr.Dataset({k: (("Omega", "F", "t_eval"), np.repeat(v[..., None], 2, -1)) for k, v in
                     (("GIM", g + d), ("LIM", g ** 2 + d), ("GIM_diff", d), ("LIM_diff", d))},
                    coords={"Omega": Om, "F": F, "t_eval": t}, attrs={"level": 0.5, "cycles": 20})
    for k in ("F_GIM", "F_LIM"):
        nu[k] = (("Omega", "t_eval"), np.repeat((0.009 + np.abs(Om - 0.9))[:, None], 2, -1))
    return an, nu


def test_integrity_map_scales_labels_and_line_styles():
    an, nu = _maps()
    fig = integrity_maps.figure_integrity_map(an, nu)
    panels = [ax for ax in fig.axes if ax.get_title()]
    bars = [ax for ax in fig.axes if not ax.get_title()]
    assert len(panels) == 6 and all(b.get_ylabel() for b in bars)  # every colour bar labelled
    lo, hi = panels[4].collections[0].get_clim()  # GIM difference: symmetric, from the data
    assert lo == -hi and 0.03 < hi < 0.05
    dashed = [ln for ax in panels for ln in ax.lines if ln.get_linestyle() == "--"]
    assert dashed and all(ln.axes in panels[:2] for ln in dashed)  # the all-phase front: dashed, top row
    legend = {t.get_text(): h.get_linestyle() for t, h in zip(fig.legends[0].get_texts(),
                                                              fig.legends[0].legend_handles)}
    assert [ls for lab, ls in legend.items() if "every phase" in lab] == ["--"]
    text = " ".join(notes(fig))
    assert "Ψ = π" in text and "3.14" not in text and "all-phase slow flow dashed" in text
    plt.close(fig)
