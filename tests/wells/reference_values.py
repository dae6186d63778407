"""Stored values of the polynomial wells the pipeline uses (cubic, the quartic by quadrature, an
asymmetric quartic): every public number of each well on fixed inputs, and how close a run on
any machine must come to them.

``reference_values.npz`` holds what the code of commit ee37d31 (before open sides, the
cancellation fix and the root-based search bound) gave; it is never regenerated (its bits are
those of OpenBLAS's Haswell kernel with numpy's AVX-512 loops).  :func:`compute` evaluates
today's wells at the stored inputs; :data:`CHECKS` says, per quantity, how far a value may lie
from the stored one (:func:`errors`), and :func:`structure` what must be equal (shape, NaN and
inf pattern).  ``python -m tests.wells.reference_values`` measures the spread of every quantity
across OpenBLAS kernels and numpy's CPU dispatch, each in its own process, as a fraction of its
tolerance (the numbers quoted in ``test_reference_values.py``).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from safebasins.wells.polynomial import cubic, polynomial, quartic_polynomial

PATH = Path(__file__).with_name("reference_values.npz")
WELLS = {"cubic": cubic, "quartic_polynomial": quartic_polynomial,
         "asymmetric": lambda **kw: polynomial([0.0, 0.0, 0.5, -0.1, -0.25], **kw)}
EPS = np.finfo(float).eps


def draw_inputs(w, seed):
    """Energies on [0, E_b) (uniform, clustered at E_b, the last float), angles, energies of the
    phase points and points (q, p) inside the well."""
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
    return {"E": E, "theta": theta, "Et": Et, "q": q[keep][:300], "p": p[keep][:300]}


def evaluate(w, x):
    """Every public number of well ``w`` at the inputs ``x`` (:func:`draw_inputs`)."""
    E, Ep = x["E"], x["E"][x["E"] > 0]
    return {
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
        "phase_point": np.stack(w.phase_point(x["theta"], x["Et"])),
        "angle_energy": np.stack(w.angle_energy(x["q"], x["p"])),
    }


def compute(stored=None, wells=None, **well_kwargs):
    """``{"well/quantity": array}`` of the wells ``wells`` (name -> factory; default
    :data:`WELLS`) built with ``well_kwargs``, evaluated at the stored inputs when ``stored`` (the
    npz's dict) is given, else at freshly drawn ones; ``in_*`` are the freshly drawn inputs and
    ``Et/<well>`` the phase points' energies (not stored: drawn from the same generator)."""
    out = {}
    for name, make in (WELLS if wells is None else wells).items():
        w = make(**well_kwargs)
        x = draw_inputs(w, list(WELLS).index(name))
        out.update({f"{name}/in_{v}": x[v] for v in ("E", "theta", "q", "p")})
        out[f"Et/{name}"] = x["Et"]
        if stored is not None:
            x = {**x, **{v: stored[f"{name}/in_{v}"] for v in ("E", "theta", "q", "p")}}
        out.update({f"{name}/{key}": v for key, v in evaluate(w, x).items()})
    return out


# ---------------------------------------------------------------------------------- tolerances
@dataclass(frozen=True)
class Check:
    """How far a quantity may lie from the stored value.

    ``metric`` (the unit of the error, per element): "ulp" (units in the last place of the
    stored value), "rel" (``|now - ref| / |ref|``, complex ones by modulus), "log_derivative"
    (the error of ``d|q_1|/dE`` or ``d arg q_1/dE`` over the modulus of the complex logarithmic
    derivative ``d log q_1 / dE = |q_1|'/|q_1| + i arg'``, times ``|q_1|`` for the amplitude: the
    phase derivative of a symmetric well is zero and only this scale is meaningful),
    "phase_point" (``|dq| / max|limits|`` and ``|dp| / sqrt(2 E_b)``), "angle_energy" (the angle
    in radians, wrapped, and E in ulps).  The tolerance is ``tol + sep * EPS / sqrt(s)`` with
    ``s = (E_b - E) / E_b``: near the separatrix the quantities are conditioned like the
    interpolants' own accuracy floor (``64 EPS sqrt(E_b / (E_b - E))``, wells/numeric.py).
    """

    metric: str
    tol: float
    sep: float = 0.0


ULPS = Check("ulp", 4.0)
SMOOTH = Check("rel", 1e-13)
CHECKS = {
    # no LAPACK on the way (Horner's rule, the seeded generator) or Newton-polished roots
    "barriers": ULPS, "barrier_energy": ULPS, "limits": ULPS, "omega0": ULPS, "V": ULPS, "dV": ULPS,
    "turning_points": ULPS, "in_E": ULPS, "in_theta": ULPS, "in_q": ULPS, "in_p": ULPS,
    # the energy interpolants (quadrature weights by inv/matmul, Chebyshev fits by lstsq)
    "J": SMOOTH, "omega": SMOOTH, "period": SMOOTH, "dJ_dE": SMOOTH, "harmonic_amplitude": SMOOTH,
    "harmonic_phase": SMOOTH, "first_harmonic": SMOOTH,
    "harmonic_amplitude_derivative": Check("log_derivative", 1e-11, 256.0),
    "harmonic_phase_derivative": Check("log_derivative", 1e-11, 256.0),
    "phase_point": Check("phase_point", 1e-13, 64.0),
    "angle_energy": Check("angle_energy", 1e-13),
    # the largest trailing Chebyshev coefficient: a ratio of numbers at the noise floor
    "interpolation_error": Check("rel", 1e-3),
}


def _ulps(a, b):
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    out = np.zeros(b.shape)
    f = np.isfinite(b) & (a != b)
    out[f] = np.abs(a[f] - b[f]) / np.spacing(np.abs(b[f]))
    return out


def _rel(a, b):
    d = np.abs(np.asarray(a) - np.asarray(b))
    scale = np.abs(np.asarray(b))
    f = np.isfinite(d)
    out = np.zeros(np.shape(d))
    out[f] = np.where(d[f] == 0, 0.0, d[f] / np.where(scale[f] > 0, scale[f], np.finfo(float).tiny))
    return out


def _tier(check, E, Eb):
    s = np.maximum((Eb - E) / Eb, np.finfo(float).tiny)
    return check.tol + check.sep * EPS / np.sqrt(s)


def errors(key, now, ref, stored, Et=None):
    """``(err, tol)``: element-wise errors of ``now`` against ``ref`` in the unit of the check of
    ``key`` ("well/quantity") and the tolerance of each element; ``stored`` (the npz's dict)
    gives the scales, ``Et`` the phase points' energies."""
    well, quantity = key.split("/")
    check = CHECKS[quantity]
    Eb = float(stored[f"{well}/barrier_energy"])
    E = stored[f"{well}/in_E"]
    if check.metric == "ulp":
        return _ulps(now, ref), np.full(np.shape(ref), check.tol)
    if check.metric == "rel":
        return _rel(now, ref), np.full(np.shape(ref), check.tol)
    if check.metric == "log_derivative":
        Ep = E[E > 0]
        A = stored[f"{well}/harmonic_amplitude"][E > 0]
        L = np.hypot(stored[f"{well}/harmonic_amplitude_derivative"] / A, stored[f"{well}/harmonic_phase_derivative"])
        scale = A * L if quantity == "harmonic_amplitude_derivative" else L
        return np.abs(now - ref) / scale, _tier(check, Ep, Eb)
    if check.metric == "phase_point":
        lim = stored[f"{well}/limits"]
        scale = np.array([np.max(np.abs(lim[np.isfinite(lim)])), np.sqrt(2 * Eb)])[:, None]
        return np.abs(now - ref) / scale, np.broadcast_to(_tier(check, Et, Eb), ref.shape)
    if check.metric == "angle_energy":
        dtheta = np.abs(np.mod(now[0] - ref[0] + np.pi, 2 * np.pi) - np.pi)
        return np.stack([dtheta, _ulps(now[1], ref[1])]), np.stack([np.full(dtheta.shape, check.tol),
                                                                    np.full(dtheta.shape, ULPS.tol)])
    raise ValueError(f"unknown metric {check.metric!r}")


def structure(now, ref):
    """What must be equal, not close: shape, dtype, the NaN pattern and the inf pattern (with
    sign).  Returns a description of the first difference, or None."""
    if now.shape != ref.shape or now.dtype != ref.dtype:
        return f"shape/dtype {now.shape} {now.dtype} != stored {ref.shape} {ref.dtype}"
    if not np.array_equal(np.isnan(now), np.isnan(ref)):
        return f"NaN at {np.flatnonzero(np.isnan(now) != np.isnan(ref))[:5]}"
    inf_now, inf_ref = (np.where(np.isinf(x), np.sign(x.real), 0.0) for x in (now, ref))
    if not np.array_equal(inf_now, inf_ref):
        return f"inf at {np.flatnonzero(inf_now != inf_ref)[:5]}"
    return None


def worst(now, stored):
    """``{key: (largest error / tolerance, largest error)}`` of every stored quantity."""
    out = {}
    for key in sorted(stored):
        err, tol = errors(key, now[key], stored[key], stored, now.get(f"Et/{key.split('/')[0]}"))
        out[key] = (float(np.max(err / tol, initial=0.0)), float(np.max(err, initial=0.0)))
    return out


# ------------------------------------------------------------------------------- measurement
#: OpenBLAS kernels an x86-64 machine may pick (Zen selects Haswell's kernel, Prescott Katmai's)
KERNELS = ("Haswell", "SkylakeX", "Cooperlake", "Sandybridge", "Nehalem", "Core2", "Barcelona", "Prescott")
#: numpy without its AVX-512 loops (what an AVX2-only CPU runs)
NO_AVX512 = {"NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR"}


def _measure(env, out):
    code = ("import sys, numpy as np; from tests.wells.reference_values import PATH, compute; "
            "np.savez(sys.argv[1], **compute(dict(np.load(PATH))))")
    root = Path(__file__).resolve().parents[2]
    full = {**os.environ, "PYTHONPATH": str(root), **env}
    subprocess.run([sys.executable, "-c", code, out], env=full, cwd=root, check=True)
    return dict(np.load(out))


def spread(configs=None):
    """Worst error / tolerance of every quantity over ``configs`` (name -> environment), each
    run in its own process; prints a table and returns ``{key: (ratio, error)}``."""
    if configs is None:
        configs = {k: {"OPENBLAS_CORETYPE": k} for k in KERNELS}
        configs.update({f"{k}+noAVX512": {"OPENBLAS_CORETYPE": k, **NO_AVX512} for k in ("Haswell", "SkylakeX")})
    stored = dict(np.load(PATH))
    total = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, env in configs.items():
            res = worst(_measure(env, os.path.join(tmp, "x.npz")), stored)
            for key, (ratio, err) in res.items():
                if key not in total or ratio > total[key][0]:
                    total[key] = (ratio, err, name)
            print(f"{name}: worst fraction of tolerance {max(r for r, _ in res.values()):.3g}", flush=True)
    print(f"{'quantity':48s} {'metric':14s} {'error':>10s} {'/ tol':>9s}  worst in")
    for key, (ratio, err, name) in total.items():
        print(f"{key:48s} {CHECKS[key.split('/')[1]].metric:14s} {err:10.3g} {ratio:9.3g}  {name}")
    return total


if __name__ == "__main__":
    spread()
