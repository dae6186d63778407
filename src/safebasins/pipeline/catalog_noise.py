"""The noise study's experiments in the catalog (:mod:`safebasins.pipeline.catalog`): escape
probabilities of the paper's quartic and the escape equation's stochastic erosion."""
from __future__ import annotations

from safebasins.pipeline.declaration import Declaration

_NOISE = "Noise: escape probabilities and stochastic integrity"
DECLARATIONS: tuple[Declaration, ...] = (
    Declaration(
        name="noise_quartic_escape_probability", kind="escape_probability", key=("noise", "quartic_escape_probability"),
        stem="noise_quartic_escape_probability", label="Noise: escape probability of the quartic at Fig. 14's forcing",
        category=_NOISE, options={}, seed_offset=40000,
        title="Paper's quartic at Fig 14's forcing under white noise: the probability of escape",
        caption=("The paper's quartic q'' + q - q³ = F sin(Ωt + Ψ) + σ ξ(t) at Fig. 14's forcing with white noise "
                 "of amplitude σ (dp = ... dt + σ dW): the probability P_escape that a path from (q0, p0) escapes "
                 "(H0 above ξ_max, docs/noise.md) within t cycles, from an ensemble of paths per initial condition "
                 "(Philox random numbers keyed by the seed, the IC, the path and the step); in red, the "
                 "P_escape = 0.05 (dashed) and 0.5 (solid) contours of the averaged theory (the backward "
                 "Kolmogorov equation of the stochastic slow flow, docs/noise-theory.md), with no paths."),
        look=("One row per noise level, one column per evaluation time; white: no path escaped, black: every path "
              "escaped. Expect the deterministic safe basin's grey-free core to shrink and its edge to blur as σ "
              "grows, and the maps to darken with time (escape accumulates). The red contours should run along "
              "the grey edge of each map: where they leave it, the averaging (an O(F) error on the edge of the "
              "deterministic basin) or the ensemble's sampling (the Wilson interval) is at fault; the notes give "
              "the mean and largest |ΔP|.")),
    Declaration(
        name="noise_escape_erosion", kind="stochastic_erosion", key=("noise", "escape_equation_erosion"),
        stem="noise_escape_erosion", label="Noise: stochastic erosion of the escape equation",
        category=_NOISE, options={}, seed_offset=41000,
        title="Escape equation under white noise: the stochastic erosion profile against σ and F",
        caption=("Thompson's escape equation q'' + q - q² = F sin(Ωt + Ψ) + σ ξ(t): GIM, LIM and IF "
                 "(docs/stochastic-integrity.md) of the stochastic safe basin {P_escape <= ε} and of the "
                 "conservative one (the upper end of the 95% Wilson interval <= ε: safe with 95% confidence), "
                 "against σ at each F and against F at each σ, one ensemble per (F, σ), every one with the same "
                 "seed (common random numbers)."),
        look=("Solid: the basin {P_escape <= ε}; dashed: the conservative basin, below it; crosses: the averaged "
              "theory's basin (white or Ornstein-Uhlenbeck noise, the asymmetric well in its sheared phase; at σ = 0 "
              "the noise-free slow flow; the notes say when it is absent). At σ = 0 the profile is "
              "the deterministic erosion. Expect the integrity to fall with σ at every F, faster where the "
              "deterministic basin is already eroded, and the LIM to fall in steps (it is a grid radius).")),
)
