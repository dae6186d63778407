"""The 22 figures of the paper: one table read by

* ``scripts/make_notebooks.py`` (writes ``notebooks/figNN_<slug>.ipynb`` and the report captions
  ``workflow/report/figNN.rst``),
* ``workflow/rules/figures.smk`` (one Snakemake rule per figure),
* the tests.

Pure data (no heavy imports): the Snakefile imports it at parse time.

Each entry: ``slug``; ``builder`` (function of :mod:`safebasins.plotting.core`); ``inputs``
(notebook parameter name -> dataset path relative to the repository root, see
docs/contracts.md); ``options`` (extra notebook parameters = keyword arguments of the
builder: style knobs); ``paper`` (the paper's caption); ``look`` (what to look for).
"""
from __future__ import annotations

ANALYTIC = "results/data/analytic"
NUMERIC = "results/data/numeric"
PARAMS = "results/params"  # resolved parameters (t_eval lists of Figs 20-22)
FIGURE_DIR = "results/figures"
NOTEBOOK_DIR = "results/notebooks"
LOG_DIR = "results/logs/figures"


def _fcr(nn):
    return {"analytic": f"{ANALYTIC}/fcr_fig{nn}.nc"}


def _basin(nn):
    return {"analytic": f"{ANALYTIC}/basin_fig{nn}.nc"}


def _cmp(nn):
    return {"analytic": f"{ANALYTIC}/fcr_fig{nn}.nc", "numeric": f"{NUMERIC}/fcr_fig{nn}.nc"}


def _nested(nn):
    return {"analytic": f"{ANALYTIC}/basin_fig{nn}.nc", "numeric": f"{NUMERIC}/chart_fig{nn}.nc"}


_SB_LEFT_RIGHT = (
    "Left: level curves of the first integral C(γ, ξ) of eq. (18) on the resonance-manifold "
    "cylinder, the truncation level ξ = ξ_max (thick blue dashed line) and the safe basin "
    "(grey region with red boundary). Right: the same safe basin mapped to the plane of initial "
    "conditions (q0, p0) with eqs. (15), (17); the thin dashed oval is the edge of the unforced "
    "well H0 = ξ_max.")

_NESTED = (
    "Grey regions: numeric safe basins (escape chart of eq. (1), energy criterion, t_eval = the "
    "integration horizon) shaded by the scanned parameter; the shading is painted from the "
    "largest basin (lightest) to the smallest (darkest), so lighter regions contain the darker "
    "ones and white is escape common to all values. Coloured curves: analytic boundaries "
    "(isolated-resonance approximation) for the same parameter values, matched by colour and "
    "line style in the legend, which also gives the stored analytic/numeric intersection over "
    "union (IoU).")

FIGURES = {
    "01": dict(
        slug="fcr_xi_ini", builder="figure_fcr", inputs=_fcr("01"),
        options=dict(color_by="curve", show_branches=False, F_max=None),
        paper="Escape threshold versus excitation frequency for various values of ξ_ini and "
              "γ_ini = 0.25, ξ_max = 0.242.",
        look="Theoretical F_cr(Ω) for several initial energies ξ_ini (one colour each); the line "
             "style gives the mechanism (solid SM, dashed MM through γ* = π, dash-dot MM through "
             "γ* = 0, dotted SMM). Higher ξ_ini generally lowers F_cr, but the ξ_ini = 0 curve "
             "lies below some higher-energy curves on its SM part."),
    "02": dict(
        slug="fcr_gamma_ini", builder="figure_fcr", inputs=_fcr("02"),
        options=dict(color_by="curve", show_branches=False, F_max=None),
        paper="Escape threshold versus excitation frequency for various values of γ_ini and "
              "ξ_ini = 0.15, ξ_max = 0.242.",
        look="Theoretical F_cr(Ω) for several initial slow phases γ_ini (one colour each), line "
             "style = mechanism. Increasing γ_ini lowers the SM part of the curve and raises the "
             "MM part."),
    "03": dict(
        slug="fcr_mechanisms", builder="figure_fcr", inputs=_fcr("03"),
        options=dict(color_by="mechanism", show_branches=True, F_max=None),
        paper="Escape threshold versus excitation frequency for the zero IC and the truncation "
              "energy level ξ_max = 0.15. Dotted, solid and dashed lines correspond to SMM, SM "
              "and MM, respectively.",
        look="The overall threshold (thick) is coloured and styled by the mechanism that sets "
             "it: green dashed MM through the tangent point (γ = π, ξ = 0.15), blue solid SM, red "
             "dotted SMM (MM through γ = 0 where the saddle energy ξ† exceeds ξ_max). Thin faint "
             "lines continue each branch where it is not the smallest."),
    "04": dict(
        slug="fcr_xi_max", builder="figure_fcr", inputs=_fcr("04"),
        options=dict(color_by="curve", show_branches=False, F_max=None),
        paper="Escape threshold versus excitation frequency for the zero IC for various values of "
              "the threshold energy level ξ_max.",
        look="Shallower wells (smaller ξ_max) need less forcing and their resonance minimum moves "
             "towards Ω = 1 (nearly linear oscillator)."),
    "05": dict(
        slug="sbmt_island", builder="figure_rm_basin", inputs=_basin("05"), options={},
        paper="Grey region is SBMT of island kind on the (γ, ξ) cylinder (left) and on the "
              "(q0, p0) plane (right). Thick dashed line corresponds to truncation level "
              "ξ_max = 0.24. The parameters of external forcing are F = 0.0876; Ω = 0.92.",
        look=_SB_LEFT_RIGHT + " The boundary is the level curve of C tangent to ξ = ξ_max; the "
             "safe region is enclosed by it (island: it does not wrap around the cylinder)."),
    "06": dict(
        slug="sbmt_peninsula_a", builder="figure_rm_basin", inputs=_basin("06"), options={},
        paper="Peninsula SBMT for the parameters F = 0.0876, Ω = 1.04. Thick dashed line "
              "corresponds to truncation level ξ_max = 0.249.",
        look=_SB_LEFT_RIGHT + " Peninsula: the tangent level curve wraps around the cylinder and "
             "the safe region lies between it and ξ = 0 (all γ)."),
    "07": dict(
        slug="sbmt_peninsula_b", builder="figure_rm_basin", inputs=_basin("07"), options={},
        paper="Peninsula SBMT for the parameters F = 0.0876, Ω = 0.57. Thick dashed line "
              "corresponds to truncation level ξ_max = 0.21.",
        look=_SB_LEFT_RIGHT + " Peninsula far below resonance (Ω = 0.57)."),
    "08": dict(
        slug="sbst", builder="figure_rm_basin", inputs=_basin("08"), options={},
        paper="SBST for the parameters F = 0.0876, Ω = 0.57. Thick dashed line corresponds to "
              "truncation level ξ_max = 0.2499.",
        look=_SB_LEFT_RIGHT + " Saddle type: the boundary passes through the saddle (open "
             "circle) of C; the safe region lies between it and ξ = 0."),
    "09": dict(
        slug="sb_coexisting", builder="figure_rm_basin", inputs=_basin("09"), options={},
        paper="Co-existence of two types of SB with parameters F = 0.0478, Ω = 0.76. Thick "
              "dashed line corresponds to truncation level ξ_max = 0.235.",
        look=_SB_LEFT_RIGHT + " Both a maximum-type and a saddle-type region exist, so the safe "
             "basin on (q0, p0) is made of two disjoint parts."),
    "10": dict(
        slug="fcr_numeric_zero_ic", builder="figure_fcr_comparison", inputs=_cmp("10"),
        options=dict(layout="panels", bracket=True, F_max=None),
        paper="Escape threshold versus excitation frequency for different energy truncation "
              "levels ξ_max and the zero IC. Dots represent values obtained numerically, while "
              "solid curves correspond to the theoretical prediction.",
        look="One panel per ξ_max. Dots: bisection F_cr (tolerance 5e-5, 3000 EC horizon). "
             "Where escape is not monotone in F (near the resonance dip), a vertical bar spans "
             "the lowest escaping F on the scan (F_escape_low) to the F above which every scanned "
             "F escapes (F_escape_all). Agreement is best near the dip and weaker far from "
             "resonance, especially on the MM branches."),
    "11": dict(
        slug="fcr_numeric_xi_ini", builder="figure_fcr_comparison", inputs=_cmp("11"),
        options=dict(layout="overlay", bracket=True, F_max=None),
        paper="Escape threshold versus excitation frequency for various values of ξ_ini and "
              "ξ_max = 0.242, γ_ini = 0.25, Ψ = π. The notation is the same as in Figure 10.",
        look="Theory lines and numeric dots share a colour per ξ_ini; bars mark the non-monotone "
             "escape bracket where it exists."),
    "12": dict(
        slug="fcr_numeric_gamma_ini", builder="figure_fcr_comparison", inputs=_cmp("12"),
        options=dict(layout="overlay", bracket=True, F_max=None),
        paper="Escape threshold versus excitation frequency for various values of γ_ini and "
              "ξ_max = 0.242, ξ_ini = 0.15, Ψ = π. The notation is the same as in Figure 10.",
        look="Theory lines and numeric dots share a colour per γ_ini; bars mark the non-monotone "
             "escape bracket where it exists."),
    "13": dict(
        slug="sb_xi_max_a", builder="figure_nested_basins", inputs=_nested("13"),
        options=dict(param="xi_max"),
        paper="Transformation of the SB with increasing energy truncation level ξ_max. Grey "
              "regions represent the numerically obtained SBs, curves correspond to the "
              "theoretical predictions. The other parameters are F = 0.015, Ω = 1.04, Ψ = π.",
        look=_NESTED + " Same topology for every ξ_max; very good agreement. Note: the paper's "
             "text says lighter = smaller ξ_max, but the basin grows with ξ_max (a larger "
             "threshold is harder to exceed), so containment puts the larger ξ_max lighter."),
    "14": dict(
        slug="sb_xi_max_b", builder="figure_nested_basins", inputs=_nested("14"),
        options=dict(param="xi_max"),
        paper="Same as Figure 13 but for F = 0.01; Ω = 0.9; Ψ = π.",
        look=_NESTED + " For the smaller ξ_max the basin splits into disjoint parts (cf. Fig 9)."),
    "15": dict(
        slug="sb_xi_max_psi1", builder="figure_nested_basins", inputs=_nested("15"),
        options=dict(param="xi_max"),
        paper="Same as Figure 14 but for Ψ = 1.",
        look=_NESTED + " The forcing phase Ψ = 1 distorts and rotates the basins of Figure 14."),
    "16": dict(
        slug="sb_forcing_a", builder="figure_nested_basins", inputs=_nested("16"),
        options=dict(param="F"),
        paper="Transformation of the SB with increasing external forcing amplitude F. Other "
              "parameters are ξ_max = 0.18, Ω = 0.9, Ψ = π.",
        look=_NESTED + " Small forcing: numeric basins follow the theoretical boundaries."),
    "17": dict(
        slug="sb_forcing_b", builder="figure_nested_basins", inputs=_nested("17"),
        options=dict(param="F"),
        paper="Same as Figure 16 but for ξ_max = 0.22, Ω = 0.9, Ψ = π.",
        look=_NESTED + " Larger forcing: erosion by secondary resonances makes the numeric basins "
             "depart from the theory (lower IoU for the larger F)."),
    "18": dict(
        slug="period_map", builder="figure_period_map",
        inputs={"analytic": f"{ANALYTIC}/basin_fig18.nc", "numeric": f"{NUMERIC}/strobe_fig18.nc"},
        options={},
        paper="Phase portrait of 100 non-escaping trajectories of the period map for the "
              "following set of parameters: F = 0.0876, Ψ = π, Ω = 0.99, ξ_max = 0.24. Each "
              "trajectory runs for 3000 iterations. Dashed curve corresponds to the theoretically "
              "predicted boundary of the SB.",
        look="Stroboscopic points (one colour per trajectory): a large island of invariant tori "
             "around a fixed point, chains of smaller islands (e.g. a 1:6 chain) and a stochastic "
             "layer between them. The dashed theoretical boundary is a reasonable first guess of "
             "the safe region but does not capture the erosion."),
    "19": dict(
        slug="criteria_rel_diff", builder="figure_criteria",
        inputs={"numeric": f"{NUMERIC}/criteria_fig19.nc"}, options={},
        paper="Comparison of SB areas for different values of the external force amplitude F. "
              "Blue, orange and green markers correspond to the minimum, the mean, and the "
              "maximum of 5 experiments. Other parameters are the following: Ω = 0.9, Ψ = 0, "
              "ξ_max = 0.25.",
        look="Relative difference (A_q − A_E)/A_E between the displacement-criterion (DSB) and "
             "energy-criterion (ESB) safe counts from 10,000 random ICs in [−1, 1]², F = 0.001 "
             "… 0.071. Near zero for small F, growing with F."),
    "20": dict(
        slug="dsb_esb_zoom", builder="figure_dsb_esb",
        inputs={"numeric": f"{NUMERIC}/chart_fig20.nc", "params": f"{PARAMS}/fig20.yaml"},
        options=dict(t_evals=None),
        paper="Zoomed SB Escape Chart simulation for F = 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, "
              "the resolution is 300×300. Left: t_eval = 500 EC. Right: t_eval = 11,000 EC, DSB "
              "(grey) and ESB (black).",
        look="DSB (grey) always contains ESB (black). At 500 EC both boundaries are irregular "
             "(transients); at 11,000 EC they are smoother and the energy criterion gives the "
             "smoother boundary."),
    "21": dict(
        slug="dsb_esb_full", builder="figure_dsb_esb",
        inputs={"numeric": f"{NUMERIC}/chart_fig21.nc", "params": f"{PARAMS}/fig21.yaml"},
        options=dict(t_evals=None),
        paper="Entire SB Escape Chart simulation for F = 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, "
              "the resolution is 300×300. Left: t_eval = 500 EC. Right: t_eval = 11,000 EC, DSB "
              "(grey) and ESB (black).",
        look="Full view of the basins of Figure 20."),
    "22": dict(
        slug="sb_area_vs_time", builder="figure_area_vs_time",
        inputs={"numeric": f"{NUMERIC}/chart_fig21.nc", "params": f"{PARAMS}/fig22.yaml"},
        options=dict(t_evals=None),
        paper="Log of SB area in pixels fading with t_eval for DSB (dashed) and ESB (solid), "
              "F = 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, the resolution is 300×300.",
        look="Natural log of the number of safe pixels of the Figure 21 chart as a function of "
             "the evaluation time: rapid shrinking for about 2000 EC, then almost constant."),
}


def notebook_name(nn):
    return f"fig{nn}_{FIGURES[nn]['slug']}.ipynb"


def notebook_path(nn):
    return f"notebooks/{notebook_name(nn)}"


def executed_notebook_path(nn):
    return f"{NOTEBOOK_DIR}/{notebook_name(nn)}"


def figure_paths(nn):
    return f"{FIGURE_DIR}/fig{nn}.png", f"{FIGURE_DIR}/fig{nn}.pdf"


# --------------------------------------------------------------------------------------------
# beyond the paper (docs/extras.md): three figures drawn by safebasins.plotting_extras from the
# datasets of workflow/rules/extras.smk. Same fields as above, plus ``title`` (report heading);
# ``inputs`` values may be lists (passed to papermill as YAML).
# --------------------------------------------------------------------------------------------
EXTRAS_DATA = "results/data/extras"
FCR_SOURCES = ("fig10", "fig11", "fig12")
IOU_SOURCES = ("fig13", "fig14", "fig15", "fig16", "fig17")


def fourier_inputs(fcr=FCR_SOURCES, iou=IOU_SOURCES):
    """Dataset inputs of the first-harmonic figure for the chosen source figures."""
    return {"fcr": [f"{EXTRAS_DATA}/fourier_fcr_{e}.nc" for e in fcr],
            "iou": [f"{EXTRAS_DATA}/fourier_iou_{e}.nc" for e in iou]}


EXTRA_FIGURES = {
    "erosion": dict(
        builder="figure_erosion",
        inputs={"analytic": f"{EXTRAS_DATA}/erosion_analytic.nc", "numeric": f"{EXTRAS_DATA}/erosion_numeric.nc"},
        options=dict(measures=["GIM", "LIM", "IF"], xi_max=None, t_eval=None),
        title="Erosion profiles: integrity measures versus forcing amplitude",
        paper="Global (GIM), local (LIM) and integrity-factor (IF) measures of the safe basin versus the "
              "forcing amplitude F, normalised by the unforced well, for the Figs 16-17 parameters "
              "(Ω = 0.9, Ψ = π, ξ_max = 0.18 and 0.22).",
        look="Lines: slow-flow (analytic) profiles with the paper's first harmonic (solid) and the exact "
             "one (dashed). Markers: numeric profiles from one escape chart per F (energy criterion), one "
             "shade per evaluation time t_eval (light = early); coinciding markers mean the profile no "
             "longer depends on t_eval. The dotted line is the 0.5 level whose first crossing F_GIM, "
             "F_LIM, F_IF is stored in both datasets. LIM collapses when the well bottom escapes "
             "(near the zero-IC F_cr), IF degrades gradually."),
    "true_basin": dict(
        builder="figure_true_basin",
        inputs={"analytic": f"{EXTRAS_DATA}/true_basin_analytic.nc",
                "numeric": f"{EXTRAS_DATA}/true_basin_numeric.nc"},
        options=dict(xi_max=None, t_eval=None, fourier="paper"),
        title="Phase-invariant (true) safe basin",
        paper="Initial conditions that are safe whatever the forcing phase Ψ: intersection of the safe "
              "basins over equispaced phases, slow flow (left) and numerics (right), F = 0.01, Ω = 0.9, "
              "ξ_max = 0.18.",
        look="Light grey: safe for at least one phase; thin outlines: the per-phase basins coloured by Ψ; "
             "green: safe for every sampled phase, with its IF disk (thick purple, + at the centre) and LIM "
             "disk (red dashed, drawn on top: where the two coincide the outline is purple and red). The "
             "dotted black oval is the analytic all-phase basin H0 = ξ_true (continuous Ψ). Not knowing the "
             "phase leaves a small energy disk around the well bottom; the panel titles give its "
             "integrity measures."),
    "fourier": dict(
        builder="figure_fourier",
        inputs=fourier_inputs(),
        options={},
        title="First harmonic: paper versus exact",
        paper="The paper's G (eq 20, leading term of the sn Fourier series) versus the exact first "
              "harmonic G/(1 - nome), both against the numerics of the paper figures: relative F_cr "
              "error on the Figs 10-12 Ω points (top row, one panel per figure) and its RMS per curve, "
              "and IoU of the analytic and numeric safe basins of Figs 13-17 (bottom row).",
        look="Top: (theory - numeric)/numeric versus Ω, one colour per curve, paper G solid, exact "
             "dashed. Bottom left: RMS of that error per curve; bottom right: IoU per chart threshold / "
             "forcing; paired bars (paper blue, exact orange) grouped by source figure. The title gives "
             "the overall RMS error and mean IoU. Lower errors and higher IoU mean the better first "
             "harmonic; the gain of the exact one grows with F, since the harmonic enters multiplied by F."),
}


def extra_notebook_path(name):
    return f"notebooks/extra_{name}.ipynb"


def extra_executed_notebook_path(name):
    return f"{NOTEBOOK_DIR}/extra_{name}.ipynb"


def extra_figure_paths(name):
    return f"{FIGURE_DIR}/extra_{name}.png", f"{FIGURE_DIR}/extra_{name}.pdf"
