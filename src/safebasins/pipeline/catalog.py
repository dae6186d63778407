"""The experiments the package declares: the paper's 22 figures and the beyond-the-paper products.

Pure data: which config block holds each experiment, its kind (:mod:`safebasins.pipeline.registry`),
title, seed offset, and its figure's texts (the paper's caption, what to look for) and plotting
options.  Read by the registry's :func:`~safebasins.pipeline.plan.plan` (Snakefile, scripts,
notebooks, report captions, cost estimate); experiments declared in the config under
``experiments:`` take their figure texts from their kind.
"""
from __future__ import annotations

from safebasins.pipeline import catalog_noise
from safebasins.pipeline.declaration import Declaration


_SB_LEFT_RIGHT = ('Left: level curves of the first integral C(γ, ξ) of eq. (18) on the resonance-manifold '
     'cylinder (γ from -π to π, widened just enough that a part of the basin crossing the cut γ = ±π is drawn '
     'whole, the cut then marked by dotted verticals), the truncation level ξ = ξ_max (thick blue dashed line), '
     'energies above the barrier (light grey band) and the safe basin (grey region with red boundary). Right: the '
     'same safe basin mapped to the plane of initial conditions (q0, p0) with eqs. (15), (17); the thin dashed oval '
     'is the edge of the unforced well H0 = ξ_max. Numeric check (one rule for Figs 5-9, stated with its numbers '
     'below): orange hatching marks the analytic-safe ICs that escape in the numerics; a connected part of the '
     'basin that the numerics do not confirm has a dotted dark-orange boundary on both panels and is left out of '
     'the classification in the title.')

_NESTED = ('Grey regions: numeric safe basins (escape chart of eq. (1), energy criterion, t_eval = the '
     'integration horizon) shaded by the scanned parameter; the shading is painted from the '
     'largest basin (lightest) to the smallest (darkest), so lighter regions contain the darker '
     'ones and white is escape common to all values. Coloured curves: analytic boundaries '
     '(isolated-resonance approximation) for the same parameter values, matched by colour and line '
     'style in the legend, which also gives the stored analytic/numeric intersection over union '
     '(IoU). Boundaries of several values that run within a few chart pixels of each other are drawn as '
     'one line of alternating colours and named in the legend.')

DECLARATIONS: tuple[Declaration, ...] = (
    Declaration(
        name="fig01", kind="fcr_theory", key=("figures", "fig01"), stem="fig01_fcr_xi_ini",
        label="Fig. 1", category="Figures", options={'color_by': 'curve', 'show_branches': False, 'F_max': None},
        title=('Critical forcing F_cr(Omega) for several initial energies xi_ini (gamma_ini = '
               '0.25, xi_max = 0.242)'),
        caption=('Escape threshold versus excitation frequency for various values of ξ_ini and '
                 'γ_ini = 0.25, ξ_max = 0.242.'),
        look=('Theoretical F_cr(Ω) for several initial energies ξ_ini (one colour each); the line '
              'style gives the mechanism that sets F_cr (legend; the styles that occur are listed '
              'below). Compare the curves\' minima (below) for the ordering in ξ_ini.')),
    Declaration(
        name="fig02", kind="fcr_theory", key=("figures", "fig02"), stem="fig02_fcr_gamma_ini",
        label="Fig. 2", category="Figures", options={'color_by': 'curve', 'show_branches': False, 'F_max': None},
        title=('Critical forcing F_cr(Omega) for several initial angles gamma_ini (xi_ini = 0.15, '
               'xi_max = 0.242)'),
        caption=('Escape threshold versus excitation frequency for various values of γ_ini and '
                 'ξ_ini = 0.15, ξ_max = 0.242.'),
        look=('Theoretical F_cr(Ω) for several initial slow phases γ_ini (one colour each); the line '
              'style gives the mechanism that sets F_cr (legend; the styles that occur are listed below).')),
    Declaration(
        name="fig03", kind="fcr_theory", key=("figures", "fig03"), stem="fig03_fcr_mechanisms",
        label="Fig. 3", category="Figures", options={'color_by': 'mechanism', 'show_branches': True, 'F_max': None},
        title=('Critical forcing F_cr(Omega) for the zero IC, xi_max = 0.15: SMM, SM and MM '
               'branches'),
        caption=('Escape threshold versus excitation frequency for the zero IC and the truncation '
                 'energy level ξ_max = 0.15. Dotted, solid and dashed lines correspond to SMM, SM '
                 'and MM, respectively.'),
        look=('The overall threshold F_cr (thick) is coloured and styled by the mechanism that sets it: '
              'MM through the tangent point at γ* = 0 (purple dash-dot) or γ* = π (green dashed), SM (blue '
              'solid), SMM (red dotted). F_cr is the largest of the branches at each Ω, not the smallest: the '
              'IC escapes only once F exceeds every obstacle its level curve meets, so the operative branch is '
              'the top one and a lower branch cannot cause escape (below). Thin lines in the same colour and '
              'style continue each branch where it lies below F_cr; a branch that never sets F_cr appears thin '
              'only. The legend lists every branch drawn.')),
    Declaration(
        name="fig04", kind="fcr_theory", key=("figures", "fig04"), stem="fig04_fcr_xi_max",
        label="Fig. 4", category="Figures", options={'color_by': 'curve', 'show_branches': False, 'F_max': None},
        title='Critical forcing F_cr(Omega) for the zero IC and several truncation levels xi_max',
        caption=('Escape threshold versus excitation frequency for the zero IC for various values '
                 'of the threshold energy level ξ_max.'),
        look=('One colour per truncation level ξ_max, line style = mechanism. Shallower wells (smaller '
              'ξ_max) need less forcing and their resonance minimum moves towards the linear natural '
              'frequency (minima below).')),
    Declaration(
        name="fig05", kind="basin_rm", key=("figures", "fig05"), stem="fig05_sbmt_island",
        label="Fig. 5", category="Figures", options={},
        title='Safe basin of maximum type, island kind (F = 0.0876, Omega = 0.92, xi_max = 0.24)',
        caption=('Grey region is SBMT of island kind on the (γ, ξ) cylinder (left) and on the (q0, '
                 'p0) plane (right). Thick dashed line corresponds to truncation level ξ_max = '
                 '0.24. The parameters of external forcing are F = 0.0876; Ω = 0.92.'),
        look=_SB_LEFT_RIGHT + " " + ('The boundary is the level curve of C tangent to ξ = ξ_max; the safe region is '
              'enclosed by it (island: it does not wrap around the cylinder).')),
    Declaration(
        name="fig06", kind="basin_rm", key=("figures", "fig06"), stem="fig06_sbmt_peninsula_a",
        label="Fig. 6", category="Figures", options={},
        title=('Safe basin of maximum type, peninsula kind (F = 0.0876, Omega = 1.04, xi_max = '
               '0.249)'),
        caption=('Peninsula SBMT for the parameters F = 0.0876, Ω = 1.04. Thick dashed line '
                 'corresponds to truncation level ξ_max = 0.249.'),
        look=_SB_LEFT_RIGHT + " " + ('Peninsula: the tangent level curve wraps around the cylinder and the safe region '
              'lies between it and ξ = 0 (all γ).')),
    Declaration(
        name="fig07", kind="basin_rm", key=("figures", "fig07"), stem="fig07_sbmt_peninsula_b",
        label="Fig. 7", category="Figures", options={},
        title=('Safe basin of maximum type, peninsula kind (F = 0.0876, Omega = 0.57, xi_max = '
               '0.21)'),
        caption=('Peninsula SBMT for the parameters F = 0.0876, Ω = 0.57. Thick dashed line '
                 'corresponds to truncation level ξ_max = 0.21.'),
        look=_SB_LEFT_RIGHT + " " + 'Peninsula far below the resonance.'),
    Declaration(
        name="fig08", kind="basin_rm", key=("figures", "fig08"), stem="fig08_sbst",
        label="Fig. 8", category="Figures", options={},
        title='Safe basin of saddle type (F = 0.0876, Omega = 0.57, xi_max = 0.2499)',
        caption=('SBST for the parameters F = 0.0876, Ω = 0.57. Thick dashed line corresponds to '
                 'truncation level ξ_max = 0.2499.'),
        look=_SB_LEFT_RIGHT + " " + ('Saddle type: the boundary passes through the saddle (open circle) of C; the safe '
              'region lies between it and ξ = 0. The thin slow-flow islands just below ξ_max are marked by the '
              'numeric check.')),
    Declaration(
        name="fig09", kind="basin_rm", key=("figures", "fig09"), stem="fig09_sb_coexisting",
        label="Fig. 9", category="Figures", options={},
        title='Coexisting safe basins of both types (F = 0.0478, Omega = 0.76, xi_max = 0.235)',
        caption=('Co-existence of two types of SB with parameters F = 0.0478, Ω = 0.76. Thick '
                 'dashed line corresponds to truncation level ξ_max = 0.235.'),
        look=_SB_LEFT_RIGHT + " " + ('Both a maximum-type and a saddle-type region exist, so the slow-flow safe basin '
                                     'on '
              '(q0, p0) is made of two disjoint parts; the numeric check judges each part on its own.')),
    Declaration(
        name="fig10", kind="fcr_compare", key=("figures", "fig10"), stem="fig10_fcr_numeric_zero_ic",
        label="Fig. 10", category="Figures", options={'layout': 'panels', 'bracket': True, 'F_max': None},
        title='Analytic versus numeric F_cr(Omega), zero IC, three truncation levels',
        caption=('Escape threshold versus excitation frequency for different energy truncation '
                 'levels ξ_max and the zero IC. Dots represent values obtained numerically, while '
                 'solid curves correspond to the theoretical prediction.'),
        look=('One panel per ξ_max. Line: theory; dots: numeric bisection F_cr (tolerance and horizon '
              'below). Where escape is not monotone in F, a black bar with caps spans the lowest '
              'escaping F on the scan (F_escape_low) to the F above which every scanned F escapes '
              '(F_escape_all), and a black ring marks the point (the bar itself is often short).')),
    Declaration(
        name="fig11", kind="fcr_compare", key=("figures", "fig11"), stem="fig11_fcr_numeric_xi_ini",
        label="Fig. 11", category="Figures", options={'layout': 'overlay', 'bracket': True, 'F_max': None},
        title=('Analytic versus numeric F_cr(Omega), several xi_ini (gamma_ini = 0.25, Psi = pi, '
               'xi_max = 0.242)'),
        caption=('Escape threshold versus excitation frequency for various values of ξ_ini and '
                 'ξ_max = 0.242, γ_ini = 0.25, Ψ = π. The notation is the same as in Figure 10.'),
        look=('Theory lines and numeric markers share a colour (qualitative palette) and each curve has '
              'its own marker shape; black bars with a ring mark the non-monotone escape brackets. The error is '
              'split below by the mechanism of the theory: the SM side (below the resonance, where F_cr is '
              'large) and the MM side.')),
    Declaration(
        name="fig12", kind="fcr_compare", key=("figures", "fig12"), stem="fig12_fcr_numeric_gamma_ini",
        label="Fig. 12", category="Figures", options={'layout': 'overlay', 'bracket': True, 'F_max': None},
        title=('Analytic versus numeric F_cr(Omega), several gamma_ini (xi_ini = 0.15, Psi = pi, '
               'xi_max = 0.242)'),
        caption=('Escape threshold versus excitation frequency for various values of γ_ini and '
                 'ξ_max = 0.242, ξ_ini = 0.15, Ψ = π. The notation is the same as in Figure 10.'),
        look=('Theory lines and numeric markers share a colour (qualitative palette) and each curve has '
              'its own marker shape; black bars with a ring mark the non-monotone escape brackets. The error is '
              'split below by the mechanism of the theory: the SM side (below the resonance, where F_cr is '
              'large) and the MM side.')),
    Declaration(
        name="fig13", kind="basin_chart", key=("figures", "fig13"), stem="fig13_sb_xi_max_a",
        label="Fig. 13", category="Figures", options={},
        title=('Safe basins versus xi_max, analytic and numeric (F = 0.015, Omega = 1.04, Psi = '
               'pi)'),
        caption=('Transformation of the SB with increasing energy truncation level ξ_max. Grey '
                 'regions represent the numerically obtained SBs, curves correspond to the '
                 'theoretical predictions. The other parameters are F = 0.015, Ω = 1.04, Ψ = π.'),
        look=_NESTED + " " + ("Same topology for every ξ_max; very good agreement. Note: the paper's text says "
              'lighter = smaller ξ_max, but the basin grows with ξ_max (a larger threshold is '
              'harder to exceed), so containment puts the larger ξ_max lighter.')),
    Declaration(
        name="fig14", kind="basin_chart", key=("figures", "fig14"), stem="fig14_sb_xi_max_b",
        label="Fig. 14", category="Figures", options={},
        title='Safe basins versus xi_max, analytic and numeric (F = 0.01, Omega = 0.9, Psi = pi)',
        caption='Same as Figure 13 but for F = 0.01; Ω = 0.9; Ψ = π.',
        look=_NESTED + " " + 'For the smaller ξ_max the basin splits into disjoint parts (cf. Fig 9).'),
    Declaration(
        name="fig15", kind="basin_chart", key=("figures", "fig15"), stem="fig15_sb_xi_max_psi1",
        label="Fig. 15", category="Figures", options={},
        title='Safe basins versus xi_max, analytic and numeric (F = 0.01, Omega = 0.9, Psi = 1)',
        caption='Same as Figure 14 but for Ψ = 1.',
        look=_NESTED + " " + 'The forcing phase of this figure distorts and rotates the basins of Figure 14.'),
    Declaration(
        name="fig16", kind="basin_chart", key=("figures", "fig16"), stem="fig16_sb_forcing_a",
        label="Fig. 16", category="Figures", options={},
        title='Safe basins versus F, analytic and numeric (xi_max = 0.18, Omega = 0.9, Psi = pi)',
        caption=('Transformation of the SB with increasing external forcing amplitude F. Other '
                 'parameters are ξ_max = 0.18, Ω = 0.9, Ψ = π.'),
        look=_NESTED + " " + 'Small forcing: numeric basins follow the theoretical boundaries.'),
    Declaration(
        name="fig17", kind="basin_chart", key=("figures", "fig17"), stem="fig17_sb_forcing_b",
        label="Fig. 17", category="Figures", options={},
        title='Safe basins versus F, analytic and numeric (xi_max = 0.22, Omega = 0.9, Psi = pi)',
        caption='Same as Figure 16 but for ξ_max = 0.22, Ω = 0.9, Ψ = π.',
        look=_NESTED + " " + ('Larger forcing: erosion by secondary resonances makes the numeric basins depart '
              'from the theory (lower IoU for the larger F).')),
    Declaration(
        name="fig18", kind="strobe", key=("figures", "fig18"), stem="fig18_period_map",
        label="Fig. 18", category="Figures", options={}, seed_offset=18000,
        title=('Stroboscopic map of non-escaping trajectories (F = 0.0876, Omega = 0.99, Psi = pi, '
               'xi_max = 0.24)'),
        caption=('Phase portrait of 100 non-escaping trajectories of the period map for the '
                 'following set of parameters: F = 0.0876, Ψ = π, Ω = 0.99, ξ_max = 0.24. Each '
                 'trajectory runs for 3000 iterations. Dashed curve corresponds to the '
                 'theoretically predicted boundary of the SB.'),
        look=('Stroboscopic points of each orbit, coloured by its class (safebasins.analysis.period_map): '
              'tori of the main island in blue (darker = larger rotation number about the central elliptic '
              'fixed point, x), each island chain in its own colour with its elliptic periodic orbit (+, '
              'found by Newton), labelled m:k by its rotation number m/k about the centre (the paper\'s 1:6) or, '
              'when it does not turn about the centre (rotation 0), by its period k, and a letter; chaotic '
              'orbits of the stochastic layer in black. Green circles: the line of initial conditions drawn '
              'first, the rest are seeded random. Dashed: the theoretical SB boundary; dotted: the well edge '
              'H0 = ξ_max. The escape criterion of the map is in the title.')),
    Declaration(
        name="fig19", kind="criteria", key=("figures", "fig19"), stem="fig19_criteria_rel_diff",
        label="Fig. 19", category="Figures", options={}, seed_offset=19000,
        title='Energy versus displacement escape criterion: safe-basin areas of random ICs',
        caption=('Comparison of SB areas for different values of the external force amplitude F. '
                 'Blue, orange and green markers correspond to the minimum, the mean, and the '
                 'maximum of 5 experiments. Other parameters are the following: Ω = 0.9, Ψ = 0, '
                 'ξ_max = 0.25.'),
        look=('Relative difference (A_q − A_E)/A_E between the displacement-criterion (DSB) and '
              'energy-criterion (ESB) safe counts of random ICs: minimum, mean and maximum over the '
              'repetitions per F.')),
    Declaration(
        name="fig20", kind="chart", key=("figures", "fig20"), stem="fig20_dsb_esb_zoom",
        label="Fig. 20", category="Figures", options={'t_evals': None},
        title='Escape chart, zoomed window (F = 0.0876, Omega = 0.95, Psi = pi, xi_max = 0.25)',
        caption=('Zoomed SB Escape Chart simulation for F = 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, '
                 'the resolution is 300×300. Left: t_eval = 500 EC. Right: t_eval = 11,000 EC, DSB '
                 '(grey) and ESB (black).'),
        look=('DSB (grey) under ESB (black); left the first, right the last evaluation time of the '
              'experiment (panel titles). A pixel is safe when its trajectory has not escaped by t_eval. Whether '
              'the paper\'s transient irregularity at the short t_eval is reproduced is said below.')),
    Declaration(
        name="fig21", kind="chart", key=("figures", "fig21"), stem="fig21_dsb_esb_full",
        label="Fig. 21", category="Figures", options={'t_evals': None},
        title='Escape chart, entire window (F = 0.0876, Omega = 0.95, Psi = pi, xi_max = 0.25)',
        caption=('Entire SB Escape Chart simulation for F = 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, '
                 'the resolution is 300×300. Left: t_eval = 500 EC. Right: t_eval = 11,000 EC, DSB '
                 '(grey) and ESB (black).'),
        look=('Full view of the basins of Figure 20: DSB (grey) under ESB (black), left the first, right the '
              'last evaluation time. Whether the paper\'s transient irregularity is reproduced is said below.')),
    Declaration(
        name="fig22", kind="area_time", key=("figures", "fig22"), stem="fig22_sb_area_vs_time",
        label="Fig. 22", category="Figures", options={'t_evals': None},
        title='Safe-basin area versus evaluation time (read from the Fig 21 chart)',
        caption=('Log of SB area in pixels fading with t_eval for DSB (dashed) and ESB (solid), F '
                 '= 0.0876, Ω = 0.95, Ψ = π, ξ_max = 0.25, the resolution is 300×300.'),
        look=('Natural log of the number of safe pixels of the Figure 21 chart versus the evaluation time, DSB '
              'dashed, ESB solid. Left, as in the paper: a linear time axis with one point per configured '
              't_eval. Right: a logarithmic axis starting at one cycle, so that the early transient shows. Dotted '
              'verticals mark the last energy escape and the time from which the DSB area stays close to its '
              'final value. Whether the paper\'s shrinking over about 2000 EC is reproduced is said below.')),
    Declaration(
        name="extra_erosion", kind="erosion", key=("extras", "erosion"), stem="extra_erosion",
        label='Erosion profiles: integrity measures versus forcing amplitude', category="Beyond the paper",
        options={'measures': ['GIM', 'LIM', 'IF'], 'xi_max': None, 't_eval': None},
        title=('Erosion profiles: GIM, LIM and IF versus F, analytic (paper and exact G) and '
               'numeric'),
        caption=('Global (GIM), local (LIM) and integrity-factor (IF) measures of the safe basin '
                 'versus the forcing amplitude F, normalised by the unforced well, for the Figs '
                 '16-17 parameters (Ω = 0.9, Ψ = π, ξ_max = 0.18 and 0.22).'),
        look=("Lines: slow-flow (analytic) profiles with the paper's first harmonic (solid) and "
              'the exact one (dashed), computed on a finer IC grid than the charts. Markers: numeric '
              'profiles from one escape chart per F (energy criterion), one shade and size per evaluation '
              'time t_eval (large and light = early), in the colour of their ξ_max (legend alike); '
              'coinciding markers mean the profile no longer depends on t_eval. The dotted line is the '
              'level whose first crossing F_GIM, F_LIM, F_IF is stored in both datasets.')),
    Declaration(
        name="extra_true_basin", kind="true_basin", key=("extras", "true_basin"), stem="extra_true_basin",
        label='Phase-invariant (true) safe basin', category="Beyond the paper",
        options={'xi_max': None, 't_eval': None, 'fourier': 'paper'},
        title='Phase-invariant (true) safe basin: intersection over the forcing phase Psi',
        caption=('Initial conditions that are safe whatever the forcing phase Ψ: intersection of '
                 'the safe basins over equispaced phases, slow flow (left) and numerics (right), F '
                 '= 0.01, Ω = 0.9, ξ_max = 0.18.'),
        look=('Light grey: safe for at least one phase; thin outlines: the per-phase basins coloured by '
              'Ψ (colour bar; analytic panel: the slow flow\'s boundary curves; numeric panel: outlines of the chart '
              'pixels); green: safe for every sampled phase, with its IF disk (thick purple, + at the '
              'centre) and LIM disk (red dashed, drawn on top: where the two coincide the outline is purple '
              'and red). The dotted black oval, on both panels, is the analytic all-phase basin H0 = ξ_true '
              '(continuous Ψ). The panel titles give the integrity measures.')),
    Declaration(
        name="extra_fourier", kind="fourier_compare", key=("extras", "fourier_compare"), stem="extra_fourier",
        label='First harmonic: paper versus exact', category="Beyond the paper", options={},
        title=("First harmonic of the slow flow: paper's G (eq 20) versus the exact one, against "
               'the numerics'),
        caption=("The paper's G (eq 20, leading term of the sn Fourier series) versus the exact "
                 'first harmonic G/(1 - nome), both against the numerics of the paper figures: '
                 'relative F_cr error on the Figs 10-12 Ω points (top row, one panel per figure) '
                 'and its RMS per curve, and IoU of the analytic and numeric safe basins of Figs '
                 '13-17 (bottom row).'),
        look=('Top: (theory - numeric)/numeric versus Ω, one colour per curve, paper G solid, '
              'exact dashed. Bottom left: RMS of that error per curve; bottom right: IoU per chart '
              'threshold / forcing; paired bars (paper blue, exact orange) grouped by source '
              'figure. The title gives the overall RMS error and mean IoU. Lower errors and higher '
              'IoU mean the better first harmonic; the gain of the exact one grows with F, since '
              'the harmonic enters multiplied by F.')),
)

# ---------------------------------------------------------------- the escape equation
# The same kinds, rules and plotting on the cubic well V = q^2/2 - q^3/3 (config block
# `escape_equation`, every entry with `well: cubic`): the paper's open problem, a well without
# closed-form action-angle variables (numeric action-angle, safebasins.wells.numeric).
_CUBIC = "Escape equation (cubic well)"
_CUBIC_NOTE = ("Escape equation q'' + q - q² = F sin(Ωt + Ψ) (V = q²/2 - q³/3, barrier energy 1/6 at q = 1, "
               "no barrier for q < 0): the isolated-resonance method with numeric action-angle variables "
               "and the exact first harmonic q₁(ξ) (complex: the well is asymmetric).")
DECLARATIONS += (
    Declaration(
        name="cubic_fcr_zero", kind="fcr_compare", key=("escape_equation", "fcr_zero"), stem="cubic_fcr_zero_ic",
        label="Escape equation: F_cr(Ω), zero IC", category=_CUBIC,
        options={'layout': 'panels', 'bracket': True, 'F_max': None},
        title="Escape equation: analytic versus numeric F_cr(Omega), zero IC, three truncation levels",
        caption=_CUBIC_NOTE + " Escape threshold versus forcing frequency for three truncation levels "
                "below the barrier energy and the zero IC (the analogue of Figure 10).",
        look=("One panel per ξ_max. Line: slow-flow theory; dots: numeric bisection F_cr of the escape "
              "equation (energy criterion). Black bars with caps mark non-monotone escape brackets.")),
    Declaration(
        name="cubic_fcr_ic", kind="fcr_compare", key=("escape_equation", "fcr_ic"), stem="cubic_fcr_nonzero_ic",
        label="Escape equation: F_cr(Ω), non-zero IC", category=_CUBIC,
        options={'layout': 'panels', 'bracket': True, 'F_max': None},
        title="Escape equation: analytic versus numeric F_cr(Omega), non-zero IC, three truncation levels",
        caption=_CUBIC_NOTE + " Escape threshold versus forcing frequency for a non-zero initial "
                "condition (ξ_ini, γ_ini, Ψ) at three truncation levels (the analogue of Figures 11-12).",
        look=("One panel per ξ_max. The IC is the phase point of the unforced orbit of energy ξ_ini at "
              "angle γ_ini + Ψ (numeric action-angle). Line: theory; dots: numerics.")),
    Declaration(
        name="cubic_basins_xi", kind="basin_chart", key=("escape_equation", "basins_xi"), stem="cubic_sb_xi_max",
        label="Escape equation: safe basins versus ξ_max", category=_CUBIC, options={},
        title="Escape equation: safe basins versus xi_max, analytic and numeric",
        caption=_CUBIC_NOTE + " Safe basins for several truncation levels at one forcing (the analogue "
                "of Figures 13-15).",
        look=_NESTED + " The basins are not symmetric under (q, p) -> (-q, -p): the well is not."),
    Declaration(
        name="cubic_basins_small_F", kind="basin_chart", key=("escape_equation", "basins_small_F"),
        stem="cubic_sb_forcing_small", label="Escape equation: safe basins at small F", category=_CUBIC,
        options={}, title="Escape equation: safe basins versus small F, analytic and numeric",
        caption=_CUBIC_NOTE + " Safe basins for small forcing amplitudes (the analogue of Figure 16).",
        look=_NESTED),
    Declaration(
        name="cubic_basins_large_F", kind="basin_chart", key=("escape_equation", "basins_large_F"),
        stem="cubic_sb_forcing_large", label="Escape equation: safe basins at larger F", category=_CUBIC,
        options={}, title="Escape equation: safe basins versus larger F, analytic and numeric",
        caption=_CUBIC_NOTE + " Safe basins for larger forcing amplitudes (the analogue of Figure 17).",
        look=_NESTED + " Erosion shows where the numeric basins lose pixels the theory keeps (lower IoU)."),
    Declaration(
        name="cubic_erosion", kind="erosion", key=("escape_equation", "erosion"), stem="cubic_erosion",
        label="Escape equation: erosion profiles", category=_CUBIC,
        options={'measures': ['GIM', 'LIM', 'IF'], 'xi_max': None, 't_eval': None},
        title="Escape equation: erosion profiles GIM, LIM and IF versus F, analytic and numeric",
        caption=_CUBIC_NOTE + " Integrity measures of the safe basin versus the forcing amplitude, "
                "normalised by the unforced well H0 < ξ_max.",
        look=("Lines: slow-flow profiles (exact first harmonic) on a finer IC grid; markers: numeric "
              "profiles from one escape chart per F, one shade per evaluation time.")),
    Declaration(
        name="cubic_true_basin", kind="true_basin", key=("escape_equation", "true_basin"), stem="cubic_true_basin",
        label="Escape equation: phase-invariant safe basin", category=_CUBIC,
        options={'xi_max': None, 't_eval': None, 'fourier': 'exact'},
        title="Escape equation: phase-invariant (true) safe basin, intersection over Psi",
        caption=_CUBIC_NOTE + " Initial conditions safe whatever the forcing phase Ψ, slow flow (left) "
                "and numerics (right).",
        look=("Green: safe for every sampled phase; thin outlines: the per-phase basins coloured by Ψ (colour "
              "bar); dotted oval: the analytic all-phase basin H0 = ξ_true.")),
)

# ---------------------------------------------------------------- other wells
# The same kinds on the pendulum and the sech^2 well (config block `other_wells`), named
# expression wells: non-polynomial potentials, one with an asymptote instead of a barrier.
_OTHER = "Other wells: pendulum and sech²"
_PENDULUM_NOTE = ("Pendulum q'' + sin q = F sin(Ωt + Ψ) (V = 1 - cos q, barriers q = ±π with energy 2, ω₀ = 1: "
                  "escape is capsize), written as the expression well '1 - cos(q)'.")
_SECH2_NOTE = ("Pöschl–Teller well V = tanh² q = 1 - sech² q (ω₀ = √2): no barrier, V tends to 1 on both sides, "
               "so the escape energy is the asymptote E_b = 1 and every truncation level lies below it.")
DECLARATIONS += tuple(
    d for well, note in (("pendulum", _PENDULUM_NOTE), ("sech2", _SECH2_NOTE)) for d in (
        Declaration(
            name=f"{well}_fcr", kind="fcr_compare", key=("other_wells", f"{well}_fcr"), stem=f"{well}_fcr_zero_ic",
            label=f"{'Pendulum' if well == 'pendulum' else 'sech² well'}: F_cr(Ω), zero IC", category=_OTHER,
            options={'layout': 'panels', 'bracket': True, 'F_max': None},
            title=f"{'Pendulum' if well == 'pendulum' else 'sech^2 well'}: analytic versus numeric F_cr(Omega), "
                  "zero IC, three truncation levels",
            caption=note + " Escape threshold versus forcing frequency for three truncation levels and the zero "
                           "IC (the analogue of Figure 10).",
            look=("One panel per ξ_max. Line: slow-flow theory (numeric action-angle variables, exact first "
                  "harmonic); dots: numeric bisection F_cr (energy criterion). Black bars with caps mark "
                  "non-monotone escape brackets.")),
        Declaration(
            name=f"{well}_basins", kind="basin_chart", key=("other_wells", f"{well}_basins"),
            stem=f"{well}_sb_xi_max", label=f"{'Pendulum' if well == 'pendulum' else 'sech² well'}: safe basins",
            category=_OTHER, options={},
            title=f"{'Pendulum' if well == 'pendulum' else 'sech^2 well'}: safe basins versus xi_max, analytic "
                  "and numeric",
            caption=note + " Safe basins for three truncation levels at one forcing (the analogue of Figures "
                           "13-15).",
            look=_NESTED),
    ))

# ---------------------------------------------------------------- damping
# q'' + beta q' + V'(q) = F sin(Omega t + Psi) (config block `damped`): Thompson's escape equation
# across the Melnikov tangency of its hilltop saddle, and the paper's quartic with small damping.
_DAMPED = "Damping: the escape equation across the Melnikov tangency and the damped quartic"
_MEASURES_CAPTION = (
    "{system}, β, Ω, Ψ in the title: the fate of each initial condition on a grid, read from the stroboscopic map "
    "(escape over ξ_max, or the attractor inside the well it settles on), at forcing amplitudes below and past "
    "the Melnikov threshold F_M of the hilltop saddle, and the fractal measures of the basin boundaries "
    "(docs/basin-measures.md): basin entropy S_b, S_bb with the log 2 criterion (Daza et al. 2016), the ball "
    "test for a fractal boundary (Puy et al. 2021), the Wada test of three basins (merging method, Daza et al. "
    "2018) and the uncertainty exponent α of the grid, each with its standard error, for two labellings: "
    "escape (escaped or safe) and attractors (escaped or each attractor's basin).")
_MEASURES_LOOK = (
    "Top: the basins at each F (white: escaped; colours: the attractors). Bottom left: the ball S_bb of the "
    "fractal test with its standard error against the band of a smooth boundary (grey) and log 2 (dotted); "
    "bottom right: α (1: smooth). Expect the escape boundary smooth below F_M and tangled past it, where the "
    "hilltop saddle's manifolds cross. The ball test's smooth value is that of two basins: where three basins "
    "meet in a ball (the share is in the notes) S_bb rises above it without a fractal boundary, so in the "
    "attractor labelling read it with that share and with α.")
_FATAL_SHOCK_CAPTION = (
    "{system}, β, Ω and ξ_max in the title: the minimal fatal shock (MFS, docs/fatal-shock.md) of each stable "
    "period-1 attractor inside the well, the smallest kick d = (dq, dp) at the forcing phase φ = Ωt + Ψ that "
    "sends the steady response to escape (H0 = p²/2 + V(q) above ξ_max, or beyond a barrier) within the horizon, "
    "in the energy norm sqrt(ω0² dq² + dp²); found on a polar grid of kicks and refined by k-section in the radius "
    "and Brent over the direction. Beside it the LIM centred on the attractor (the largest safe disc on a grid of "
    "kicks), which the MFS refines: LIM minus one node diagonal <= MFS <= LIM.")
_FATAL_SHOCK_LOOK = (
    "(a) The phase plane: the escape level H0 = ξ_max (dashed), each attractor's state at the shock phases (dots, "
    "joined in phase order; ring: the section t = 0) and the arrow of its MFS to the escaping state (cross). A kick "
    "that ends on the level escapes at once; one that ends inside escapes in flight. (b) The MFS over the phase, "
    "one colour per attractor, with the grid's LIM as open markers just above it. Where a resonant and a "
    "non-resonant attractor coexist, expect the resonant one (the larger response) far easier to kick out; "
    "expect the MFS to vary with the phase the kick comes at.")
_CONTINUATION_CAPTION = (
    "{system}, β and ξ_max in the title: the period-1 attractors inside the well followed across F by "
    "pseudo-arclength continuation of the DOP853 period map (docs/continuation.md); the Floquet multipliers give "
    "their stability, and the folds, period doublings and the branch's exit from the well (the largest H0 on its "
    "orbit reaching ξ_max) are located on the way. At every swept value the basins are labelled on a grid of "
    "initial conditions over the well (the compiled stroboscopic map) and each attractor's basin is measured: "
    "GIM = its area over the unforced safe area on the same grid. A basin's Dover cliff is the step of the "
    "sweep over which the most of it escapes (grid nodes in the basin at one value that escape at the next).")
_CONTINUATION_LOOK = (
    "(a) The response curves: the largest |q| over the period against F, one colour per attractor where stable "
    "(solid), grey dashed where unstable (the saddle branch between folds); open circles: folds, diamonds: period "
    "doublings, crosses: the orbit reaching the escape energy. (b) Each attractor's GIM against F in its colour, "
    "the safe basin's (every IC that does not escape) black dashed; each attractor's cliff shaded in its colour "
    "with the GIM it loses there, the safe basin's hatched. Expect a resonant and a "
    "non-resonant attractor to coexist between the folds, and the safe basin to fall steeply just above the "
    "Melnikov tangency of the hilltop saddle, the cliff, mostly at the expense of one attractor's basin.")
DECLARATIONS += (
    Declaration(
        name="damped_tangency", kind="tangency", key=("damped", "escape_equation"), stem="damped_tangency",
        label="Damped escape equation: erosion across the Melnikov tangency", category=_DAMPED, options={},
        seed_offset=31000,
        title="Damped escape equation: integrity, boundary fractality and basins across the Melnikov tangency",
        caption=("Thompson's escape equation with damping, q'' + β q' + q - q² = F sin(Ωt + Ψ) (β, Ω, Ψ in the "
                 "title), the classic benchmark of basin erosion: the safe basin (energy criterion, H0 above the "
                 "hilltop's energy) of the long-time response versus the forcing amplitude F. The Melnikov threshold "
                 "F_M (first order in "
                 "F and β, docs/melnikov.md) is where the hilltop saddle's stable and unstable manifolds first "
                 "touch; past it the basin boundary becomes fractal and the basin erodes."),
        look=("(a) GIM, LIM and IF versus F (faint: the early evaluation time, solid: the long-time basin) with "
              "the dashed Melnikov line; (b) the uncertainty exponent α of the basin boundary (α = 1 smooth, "
              "α < 1 fractal) from seeded paired initial conditions; (c, d) the long-time safe basin (blue) "
              "before and after the tangency. Expect LIM and IF to collapse close to F_M and α to drop below 1 "
              "past it.")),
    Declaration(
        name="damped_quartic_fcr", kind="fcr_compare", key=("damped", "quartic_fcr"), stem="damped_quartic_fcr",
        label="Damped quartic: F_cr(Ω) for several β", category=_DAMPED,
        options={'layout': 'overlay', 'bracket': True, 'F_max': None},
        title="Paper's quartic with small damping: analytic versus numeric F_cr(Omega) for several beta",
        caption=("The paper's benchmark with linear damping, q'' + β q' + q - q³ = F sin(Ωt + Ψ), one initial "
                 "condition and truncation level (in the title), one curve per small damping coefficient β. Theory: "
                 "F_cr is the smallest F for which the damped slow flow "
                 "J' = -∂C/∂γ - βJ, γ' = ∂C/∂J (docs/damping.md) carries the zero IC to ξ_max before it settles "
                 "on an attractor."),
        look=("Lines: damped slow-flow theory, one colour per β; markers: numeric bisection of the damped "
              "equation (energy criterion); grey dashed: the undamped theory. Damping lifts F_cr most at the "
              "resonance dip and hardly away from it; theory and numerics should agree about as well as "
              "undamped (Fig. 10).")),
    Declaration(
        name="damped_quartic_basins", kind="basin_chart", key=("damped", "quartic_basins"),
        stem="damped_quartic_basins", label="Damped quartic: safe basins versus ξ_max (Fig. 14's forcing)",
        category=_DAMPED, options={},
        title="Paper's quartic with small damping: damped slow-flow safe basins versus numerics at Fig 14's forcing",
        caption=("Figure 14's case (the paper's quartic, same forcing and window) with linear damping β q' added "
                 "to eq. (1), at two truncation levels; β and the other parameters are in the title. With "
                 "damping C is no longer conserved and its level curves bound no basin: an IC is analytically "
                 "safe when its trajectory of the damped slow flow J' = -∂C/∂γ - βJ, γ' = ∂C/∂J "
                 "(docs/damping.md) settles on an attractor below ξ_max, and the analytic boundary is the "
                 "outline of that safe mask on the IC grid. The numerics integrate the damped equation."),
        look=(_NESTED.replace("Coloured curves: analytic boundaries", "Coloured curves: outlines of the damped "
                                                                      "slow flow's safe masks")
              + " Compare with Fig. 14: damping lets ICs whose undamped slow trajectory reaches ξ_max spiral in "
                "instead, so both the numeric and the analytic basins grow; the IoU in the legend and the notes "
                "measures how well the damped slow flow tracks that growth.")),
    Declaration(
        name="damped_escape_measures", kind="basin_measures", key=("damped", "escape_equation_measures"),
        stem="damped_escape_measures", label="Damped escape equation: fractal boundary measures",
        category=_DAMPED, options={}, seed_offset=32000,
        title="Damped escape equation: basin entropy, fractal and Wada tests below and past the Melnikov tangency",
        caption=_MEASURES_CAPTION.format(system="Thompson's escape equation q'' + β q' + q - q² = F sin(Ωt + Ψ)"),
        look=_MEASURES_LOOK),
    Declaration(
        name="damped_quartic_measures", kind="basin_measures", key=("damped", "quartic_measures"),
        stem="damped_quartic_measures", label="Damped quartic: fractal boundary measures",
        category=_DAMPED, options={}, seed_offset=33000,
        title="Paper's quartic with damping: basin entropy, fractal and Wada tests around the Melnikov threshold",
        caption=_MEASURES_CAPTION.format(system="the paper's quartic with damping, q'' + β q' + q - q³ = "
                                                "F sin(Ωt + Ψ)"),
        look=_MEASURES_LOOK),
    Declaration(
        name="damped_escape_saddle", kind="hilltop_saddle", key=("damped", "escape_equation_saddle"),
        stem="damped_escape_saddle", label="Damped escape equation: the hilltop saddle's manifolds",
        category=_DAMPED, options={},
        title="Damped escape equation: the hilltop saddle's manifolds over the escape chart, and their tangency",
        caption=("Thompson's escape equation q'' + β q' + q - q² = F sin(Ωt + Ψ) (β, Ω, Ψ in the title): the "
                 "hilltop saddle's T-periodic orbit found by multiple shooting (Newton on the stroboscopic map, "
                 "DOP853), its stable manifold W^s and unstable manifold W^u grown on the stroboscopic map of the "
                 "section t = 0, drawn over the escape chart of the same section (energy criterion at the "
                 "hilltop's energy) below and past the Melnikov threshold F_M. The F where the manifolds first "
                 "touch is found numerically (Brent on their signed distance) and compared with F_M, which is "
                 "first order in F and β (docs/melnikov.md)."),
        look=("Grey: initial conditions safe over the horizon; blue: W^s, red: W^u (solid: the branches on the "
              "well's side, dashed: outer); black dot: the saddle fixed point. Below the tangency the inner W^s "
              "is the edge of the safe basin and the inner W^u spirals onto the attractor inside it; past the "
              "tangency W^u crosses W^s and the edge of the safe basin is tangled.")),
    Declaration(
        name="damped_escape_fatal_shock", kind="minimal_fatal_shock", key=("damped", "escape_equation_fatal_shock"),
        stem="damped_escape_fatal_shock", label="Damped escape equation: the minimal fatal shock",
        category=_DAMPED, options={},
        title="Damped escape equation: the minimal fatal shock of the resonant and non-resonant attractors",
        caption=_FATAL_SHOCK_CAPTION.format(system="Thompson's escape equation q'' + β q' + q - q² = F sin(Ωt + Ψ)"),
        look=_FATAL_SHOCK_LOOK),
    Declaration(
        name="damped_quartic_fatal_shock", kind="minimal_fatal_shock", key=("damped", "quartic_fatal_shock"),
        stem="damped_quartic_fatal_shock", label="Damped quartic: the minimal fatal shock at Fig. 14's forcing",
        category=_DAMPED, options={},
        title="Paper's quartic with damping at Fig 14's forcing: the minimal fatal shock of its attractor",
        caption=_FATAL_SHOCK_CAPTION.format(system="the paper's quartic with damping, q'' + β q' + q - q³ = "
                                                   "F sin(Ωt + Ψ), at Fig. 14's forcing"),
        look=_FATAL_SHOCK_LOOK),
    Declaration(
        name="damped_escape_continuation", kind="continue_attractors", key=("damped", "escape_equation_continuation"),
        stem="damped_escape_continuation", label="Damped escape equation: the attractors followed across F",
        category=_DAMPED, options={},
        title="Damped escape equation: the resonant and non-resonant attractors across F, their basins and the cliff",
        caption=_CONTINUATION_CAPTION.format(system="Thompson's escape equation q'' + β q' + q - q² = F sin(Ωt + Ψ) "
                                                    "at Ω = 0.85"),
        look=_CONTINUATION_LOOK),
    Declaration(
        name="damped_quartic_continuation", kind="continue_attractors", key=("damped", "quartic_continuation"),
        stem="damped_quartic_continuation", label="Damped quartic: the attractors followed across F at Fig. 14's Ω",
        category=_DAMPED, options={},
        title="Paper's quartic with damping at Fig 14's Ω and Ψ: its attractors across F, their basins and the cliff",
        caption=_CONTINUATION_CAPTION.format(system="the paper's quartic with damping, q'' + β q' + q - q³ = "
                                                    "F sin(Ωt + Ψ), at Fig. 14's Ω = 0.9 and Ψ = π"),
        look=_CONTINUATION_LOOK),
)

DECLARATIONS += catalog_noise.DECLARATIONS

BY_NAME = {d.name: d for d in DECLARATIONS}
