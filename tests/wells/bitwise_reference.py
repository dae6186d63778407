"""Bit-for-bit reference of the polynomial wells the pipeline uses (cubic, the quartic by
quadrature, an asymmetric quartic): every public number of the well on fixed inputs.

``compute()`` evaluates the wells of today's code; ``bitwise_reference.npz`` holds what the code
of commit ee37d31 (before open sides, the cancellation fix and the root-based search bound)
gave on this machine.  Regenerate it only from that commit: ``python -m tests.wells.bitwise_reference``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from safebasins.wells.polynomial import cubic, polynomial, quartic_polynomial

PATH = Path(__file__).with_name("bitwise_reference.npz")
WELLS = {"cubic": cubic, "quartic_polynomial": quartic_polynomial,
         "asymmetric": lambda: polynomial([0.0, 0.0, 0.5, -0.1, -0.25])}


def _inputs(w, seed):
    """Energies on [0, E_b) (uniform, clustered at E_b, the last float), angles and phase points."""
    Eb = w.barrier_energy
    E = np.concatenate([np.linspace(0.0, Eb, 200, endpoint=False), Eb - Eb * np.geomspace(1e-3, 1e-15, 13),
                        [np.nextafter(Eb, 0.0)]])
    rng = np.random.default_rng(seed)
    theta = rng.uniform(-1.0, 7.0, 300)
    Et = np.concatenate([rng.uniform(0.0, Eb, 290), Eb * (1 - np.geomspace(1e-3, 1e-12, 10))])
    lo, hi = w.limits
    q = rng.uniform(max(lo, -3.0), min(hi, 3.0), 3000)
    p = rng.uniform(-1.0, 1.0, 3000) * np.sqrt(2 * Eb)
    keep = (w.H0(q, p) < Eb) & (q > lo) & (q < hi)
    return E, theta, Et, q[keep][:300], p[keep][:300]


def compute():
    """``{key: array}`` of every well of :data:`WELLS`."""
    out = {}
    for k, (name, make) in enumerate(WELLS.items()):
        w = make()
        E, theta, Et, q, p = _inputs(w, k)
        Ep = E[E > 0]
        vals = {
            "barriers": np.array(w.barriers), "barrier_energy": np.array(w.barrier_energy),
            "limits": np.array(w.limits), "omega0": np.array(w.omega0),
            "interpolation_error": np.array(w.interpolation_error),
            "V": w.V(np.linspace(-2, 2, 41)), "dV": w.dV(np.linspace(-2, 2, 41)),
            "J": w.J(E), "omega": w.omega(E), "period": w.period(E), "dJ_dE": w.dJ_dE(E),
            "harmonic_amplitude": w.harmonic_amplitude(E), "harmonic_phase": w.harmonic_phase(E),
            "harmonic_amplitude_derivative": w.harmonic_amplitude_derivative(Ep),
            "harmonic_phase_derivative": w.harmonic_phase_derivative(Ep),
            "first_harmonic": w.first_harmonic(E),
            "turning_points": np.stack(w.turning_points(np.append(E, w.barrier_energy))),
            "phase_point": np.stack(w.phase_point(theta, Et)),
            "angle_energy": np.stack(w.angle_energy(q, p)),
            "in_q": q, "in_p": p, "in_theta": theta, "in_E": E,
        }
        out.update({f"{name}/{key}": v for key, v in vals.items()})
    return out


if __name__ == "__main__":
    np.savez_compressed(PATH, **compute())
    print(f"wrote {PATH}")
