"""The step of the compiled engine: schemes, forcing tables and the well's force and energy.

Equation: q'' + V'(q) = F sin(Omega t + Psi), first order q' = p, p' = -V'(q) + f(t).

Schemes
-------
Blanes & Moan (2002) symmetric symplectic Runge-Kutta-Nystrom method SRKN_6^b (order 4,
7 kicks + 6 drifts per step, kick first):

    B(b1) A(a1) B(b2) A(a2) B(b3) A(a3) B(b4) A(a3) B(b3) A(a2) B(b2) A(a1) B(b1)

with A = drift q += a h p (time drifts with q: extended phase space) and B = kick
p += b h (-V'(q) + F sin(Omega t_k + Psi)) at the current sub-time t_k.  Because
Omega * t_k = 2 pi (s + c_k) / S for sub-step s of a period of S steps, the table
sin(Omega t_k + Psi) depends only on (S, Psi): one table serves every Omega and F.

Classic RK4 (integrator="rk4"): 4 force evaluations per step at t, t + h/2 (twice) and t + h,
table sin(Omega t + Psi) of shape (S, 3).  The scheme of a run is the width of its forcing
table (7: SRKN6b, 3: RK4).

Every operation is written with explicit fused multiply-adds (llvm.fma), no fast-math flags:
vector loop and scalar replay produce bitwise identical numbers.

Wells (the compile-time kernel key ``well``)
--------------------------------------------
The well enters the step through its force -V'(q) + f and the escape test through
2 H0 = p^2 + 2 V(q): wellcode.well_force / well_energy2 of the well's compiled form
(wellcode.WellCode), chosen at typing time from the kernel key, a numba literal threaded
through every call like the scheme flag.  Each key is its own compiled, cached kernel; keys
hash the arithmetic and the engine's source, so editing this file invalidates the cache.

``wpar`` (float64, ``wellcode.N_WPAR``): [q_left, q_right, w_0 .. w_13]; the barriers (+-inf
where there is none) and the well's run-time coefficients (``wtuple``).
"""
from __future__ import annotations

import numpy as np
import functools

from numba import njit, types
from numba.core import errors
from numba.extending import overload

from safebasins.numerics.wellcode import (_literal_code, cpu_functions, cpu_jit, fma, mul, quartic_code,
                                           well_energy2, well_force)

# --- Blanes & Moan 2002, SRKN_6^b (Table 3), order 4 -------------------------------------
_A1 = 0.245298957184271
_A2 = 0.604872665711080
_A3 = 0.5 - (_A1 + _A2)
_B1 = 0.0829844064174052
_B2 = 0.396309801498368
_B3 = -0.0390563049223486
_B4 = 1.0 - 2.0 * (_B1 + _B2 + _B3)
BM6_DRIFT = np.array([_A1, _A2, _A3, _A3, _A2, _A1])
BM6_KICK = np.array([_B1, _B2, _B3, _B4, _B3, _B2, _B1])
# sub-times of the 7 kicks as fractions of a step
BM6_KICK_TIMES = np.concatenate([[0.0], np.cumsum(BM6_DRIFT)])
BM6_KICK_TIMES[-1] = 1.0
DRIFT1, DRIFT2, DRIFT3 = _A1, _A2, _A3
KICK1, KICK2, KICK3, KICK4 = _B1, _B2, _B3, _B4
INTEGRATOR = "Blanes-Moan SRKN6b (symplectic RKN, order 4, 6 force evaluations/step)"
N_KICKS = 7

# --- classic RK4 --------------------------------------------------------------------------
RK4_COEF = np.array([0.5, 1.0, 1.0 / 6.0])       # h/2, h, h/6 (as products h * c)
RK4_TIMES = np.array([0.0, 0.5, 1.0])            # force sub-times as fractions of a step
RK4_C1, RK4_C2, RK4_C3 = 0.5, 1.0, 1.0 / 6.0
INTEGRATORS = {
    "srkn6b": INTEGRATOR,
    "rk4": "classic RK4 (order 4, not symplectic, 4 force evaluations/step)",
}

# --- wells: the compiled form of a well (force and energy written once) is wellcode.py ---------
#: kernel key of the paper's quartic (a global constant: numba types it as a literal)
QUARTIC_KEY = quartic_code().key


@njit(cache=True, inline="always")
def wtuple(wpar):
    """The 14 coefficients of wpar as scalars (loaded once, before the step loops)."""
    return (wpar[2], wpar[3], wpar[4], wpar[5], wpar[6], wpar[7], wpar[8],
            wpar[9], wpar[10], wpar[11], wpar[12], wpar[13], wpar[14], wpar[15])


_W0 = (0.0,) * 14


@njit(cache=True, inline="always")
def force(q, f):
    """q^3 - q + f (the quartic), with f = F sin(Omega t_k + Psi)."""
    return well_force(QUARTIC_KEY, _W0, q, f)


@njit(cache=True, inline="always")
def energy2(q, p):
    """2 H0 = p^2 + q^2 - q^4/2 of the quartic (eq 7, untruncated)."""
    return well_energy2(QUARTIC_KEY, _W0, q, p)


@njit(cache=True)
def energy(q, p):
    return 0.5 * energy2(q, p)


# --- the schemes: one source for the CPU lanes and the CUDA kernels ------------------------
#: scheme flags, a compile-time constant of the kernels (like the well's key)
SRKN6B, RK4, SRKN6B_DAMPED, RK4_DAMPED = 0, 1, 2, 3
SCHEMES = {("srkn6b", False): SRKN6B, ("rk4", False): RK4, ("srkn6b", True): SRKN6B_DAMPED,
           ("rk4", True): RK4_DAMPED}
DAMPED_INTEGRATORS = {
    "srkn6b": "conformal symplectic Blanes-Moan SRKN6b (order 4): drifts q += d_k p, p *= e_k with "
              "d_k = (1 - exp(-beta a_k h))/beta, e_k = exp(-beta a_k h), the exact flow of p' = -beta p "
              "folded into each drift",
    "rk4": "classic RK4 of q' = p, p' = -V'(q) - beta p + f (order 4, not symplectic)",
}
#: coefficients per parameter set, for every scheme (lane_coefficients), c1 .. c10:
#:   SRKN6b         a1 h, a2 h, a3 h, b1 h, b2 h, b3 h, b4 h, 0, 0, 0
#:   SRKN6b damped  d1, d2, d3, b1 h, b2 h, b3 h, b4 h, e1, e2, e3
#:   RK4            h/2, h, h/6, 0, 0, 0, 0, 0, 0, 0
#:   RK4 damped     h/2, h, h/6, 0, 0, 0, 0, beta, 0, 0
N_COEF = 10


def scheme_steps(force):
    """The steps of the four schemes (indexed by the scheme flag) for a ``force(w, q, f) =
    -V'(q) + f`` already compiled for a target: plain functions ``step(w, q, p, c1, ..., c10,
    f1, ..., f7) -> (q, p)`` that the target compiles in turn (numba.njit for the CPU lanes,
    numba.cuda.jit(device=True) for the GPU): the schemes are written once.  ``c`` are the
    scheme's coefficients (N_COEF), ``f`` the forcing values F sin(Omega t_k + Psi) at its force
    sub-times (SRKN6b: the 7 kicks; RK4: t, t + h/2, t + h, then unused).

    SRKN6b (Blanes & Moan 2002, SRKN_6^b) kicks first, B(b1) A(a1) B(b2) ... A(a1) B(b1), with
    A the drift q += a h p (time drifts with q: extended phase space) and B the kick
    p += b h (-V'(q) + f).  With damping the drift is the exact flow of q' = p, p' = -beta p over
    a h: q += d p, p *= e (d = (1 - e^{-beta a h}) / beta, e = e^{-beta a h}); in the variables
    (q, e^{beta t} p) this is the same splitting of an extended Hamiltonian with the RKN
    property, so the scheme keeps order 4 (conformal symplectic; docs/damping.md).  Every
    product that meets an add is an explicit fma; the damped p *= e is a ``mul`` (never
    contracted on the GPU)."""

    def bm6(w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
        p = fma(c4, force(w, q, f1), p)
        q = fma(c1, p, q)
        p = fma(c5, force(w, q, f2), p)
        q = fma(c2, p, q)
        p = fma(c6, force(w, q, f3), p)
        q = fma(c3, p, q)
        p = fma(c7, force(w, q, f4), p)
        q = fma(c3, p, q)
        p = fma(c6, force(w, q, f5), p)
        q = fma(c2, p, q)
        p = fma(c5, force(w, q, f6), p)
        q = fma(c1, p, q)
        p = fma(c4, force(w, q, f7), p)
        return q, p

    def bm6_damped(w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
        p = fma(c4, force(w, q, f1), p)
        q = fma(c1, p, q)
        p = mul(p, c8)
        p = fma(c5, force(w, q, f2), p)
        q = fma(c2, p, q)
        p = mul(p, c9)
        p = fma(c6, force(w, q, f3), p)
        q = fma(c3, p, q)
        p = mul(p, c10)
        p = fma(c7, force(w, q, f4), p)
        q = fma(c3, p, q)
        p = mul(p, c10)
        p = fma(c6, force(w, q, f5), p)
        q = fma(c2, p, q)
        p = mul(p, c9)
        p = fma(c5, force(w, q, f6), p)
        q = fma(c1, p, q)
        p = mul(p, c8)
        p = fma(c4, force(w, q, f7), p)
        return q, p

    def rk4(w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
        # classic RK4; hh = h/2, h, h6 = h/6; f1, f2, f3 at t, t + h/2, t + h
        k1 = force(w, q, f1)
        q2 = fma(c1, p, q)
        p2 = fma(c1, k1, p)
        k2 = force(w, q2, f2)
        q3 = fma(c1, p2, q)
        p3 = fma(c1, k2, p)
        k3 = force(w, q3, f2)
        q4 = fma(c2, p3, q)
        p4 = fma(c2, k3, p)
        k4 = force(w, q4, f3)
        sq = p2 + p3
        sp = k2 + k3
        q = fma(c3, (p + p4) + (sq + sq), q)
        p = fma(c3, (k1 + k4) + (sp + sp), p)
        return q, p

    def rk4_damped(w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
        # RK4 of p' = -V'(q) - beta p + f: each force term fma(-beta, p, force)
        nb = -c8
        k1 = fma(nb, p, force(w, q, f1))
        q2 = fma(c1, p, q)
        p2 = fma(c1, k1, p)
        k2 = fma(nb, p2, force(w, q2, f2))
        q3 = fma(c1, p2, q)
        p3 = fma(c1, k2, p)
        k3 = fma(nb, p3, force(w, q3, f2))
        q4 = fma(c2, p3, q)
        p4 = fma(c2, k3, p)
        k4 = fma(nb, p4, force(w, q4, f3))
        sq = p2 + p3
        sp = k2 + k3
        q = fma(c3, (p + p4) + (sq + sq), q)
        p = fma(c3, (k1 + k4) + (sp + sp), p)
        return q, p

    return bm6, rk4, bm6_damped, rk4_damped


@functools.cache
def cpu_steps(key):
    """The four steps of the code with kernel key ``key``, compiled for the CPU lanes (inlined)."""
    return tuple(cpu_jit(s) for s in scheme_steps(cpu_functions(key)[0]))


def _literal_scheme(scheme):
    if not isinstance(scheme, types.IntegerLiteral) or scheme.literal_value not in SCHEMES.values():
        raise errors.TypingError(f"scheme must be a compile-time constant among {sorted(SCHEMES.values())}, "
                                 f"got {scheme}")
    return scheme.literal_value


def step(scheme, well, w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
    """One step of the scheme flag `scheme` for the well with kernel key `well` (both compile-time
    constants): scheme_steps of the well's force."""
    raise NotImplementedError("step is compiled code (numba)")


@overload(step, inline="always")
def _ol_step(scheme, well, w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
    STEP = cpu_steps(_literal_code(well).key)[_literal_scheme(scheme)]

    def impl(scheme, well, w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7):
        return STEP(w, q, p, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
    return impl


@njit(cache=True, inline="always")
def bm6_step(q, p, a1, a2, a3, b1, b2, b3, b4, f1, f2, f3, f4, f5, f6, f7):
    """One SRKN6b step of the quartic."""
    return step(SRKN6B, QUARTIC_KEY, _W0, q, p, a1, a2, a3, b1, b2, b3, b4, 0.0, 0.0, 0.0,
                f1, f2, f3, f4, f5, f6, f7)


@njit(cache=True, inline="always")
def rk4_step(q, p, hh, h, h6, f1, f2, f3):
    """One RK4 step of the quartic."""
    return step(RK4, QUARTIC_KEY, _W0, q, p, hh, h, h6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                f1, f2, f3, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def row(tab, s, scheme):
    """Row s of a forcing table as 7 scalars (RK4: 3 + zeros)."""
    if scheme == RK4 or scheme == RK4_DAMPED:
        return tab[s, 0], tab[s, 1], tab[s, 2], 0.0, 0.0, 0.0, 0.0
    return tab[s, 0], tab[s, 1], tab[s, 2], tab[s, 3], tab[s, 4], tab[s, 5], tab[s, 6]


@njit(cache=True, inline="always")
def lane_coefs(scheme, h):
    """The undamped schemes' coefficients formed from the step h in the per-lane loop (the same
    IEEE products lane_coefficients precomputes)."""
    if scheme == RK4:
        return h * RK4_C1, h * RK4_C2, h * RK4_C3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return h * DRIFT1, h * DRIFT2, h * DRIFT3, h * KICK1, h * KICK2, h * KICK3, h * KICK4, 0.0, 0.0, 0.0


def check_integrator(integrator):
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {sorted(INTEGRATORS)}, got {integrator!r}")
    return integrator


def sine_table(steps_per_cycle, Psi, integrator="srkn6b"):
    """sin(Omega t + Psi) at the force sub-times of every step of one period: (S, 7) for
    SRKN6b (7 kicks), (S, 3) for RK4 (t, t + h/2, t + h).  The width selects the scheme."""
    times = BM6_KICK_TIMES if check_integrator(integrator) == "srkn6b" else RK4_TIMES
    s = np.arange(steps_per_cycle, dtype=float)[:, None] + times[None, :]
    return np.ascontiguousarray(np.sin(2.0 * np.pi * s / steps_per_cycle + Psi))


def scheme_of(integrator, damping=0.0):
    """The scheme flag of an integrator and a damping (0: the undamped schemes, bitwise as before)."""
    return SCHEMES[(check_integrator(integrator), bool(damping > 0.0))]


def lane_coefficients(Omega, steps_per_cycle, integrator="srkn6b", damping=0.0):
    """Per-parameter-set step coefficients (n, N_COEF), the layout of the scheme (see N_COEF):
    a1 h, a2 h, a3 h, b1 h, ..., b4 h (SRKN6b) or h/2, h, h/6 (RK4), then zeros; with damping
    the drifts d_k = (1 - e^{-beta a_k h})/beta = -expm1(-beta a_k h)/beta and the decays
    e_k = e^{-beta a_k h} (SRKN6b), or beta in c8 (RK4)."""
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    h = 2.0 * np.pi / (Omega * steps_per_cycle)
    out = np.zeros((Omega.size, N_COEF))
    scheme = scheme_of(integrator, damping)
    if scheme in (SRKN6B, SRKN6B_DAMPED):
        out[:, 0:3] = h[:, None] * BM6_DRIFT[None, :3]
        out[:, 3:7] = h[:, None] * BM6_KICK[None, :4]
        if scheme == SRKN6B_DAMPED:
            x = -damping * out[:, 0:3]
            out[:, 0:3] = -np.expm1(x) / damping
            out[:, 7:10] = np.exp(x)
    else:
        out[:, 0:3] = h[:, None] * RK4_COEF[None, :]
        if scheme == RK4_DAMPED:
            out[:, 7] = damping
    return out


def step_sizes(Omega, steps_per_cycle):
    """h = T / S per parameter set (the per-lane path forms h * a_k in the loop)."""
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    return 2.0 * np.pi / (Omega * steps_per_cycle)
