"""Compiled ensembles of the Langevin equation: the CPU lanes of numerics.noise.

Equation: dq = p dt, dp = (-beta p - V'(q) + F sin(Omega t + Psi)) dt + sigma dW (white noise)
or dp = (... + eta) dt with the Ornstein-Uhlenbeck force d eta = -(eta / tau) dt + (sigma / tau) dW
(coloured noise of correlation time tau; sigma_w below is sigma for white noise, 0 otherwise).

Scheme (weak order 2): the Strang splitting of the generator into the deterministic part
(drift, damping, force, eta held constant; the engine's scheme, schemes.py, with its damped
variant for beta > 0) and the noise: ``(sigma_w^2/2) d^2/dp^2``, whose exact flow over h/2 is
``p += sigma_w sqrt(h/2) Z``, and the exact Ornstein-Uhlenbeck flow of eta over h/2,
``eta = c_1 eta + c_2 Z`` (c_1 = exp(-h/(2 tau)), c_2 = sigma sqrt((1 - exp(-h/tau)) / (2 tau))):

    p += a Z_1, eta = c_1 eta + c_2 Z_1;   (q, p) = step(q, p; f + eta);   p += a Z_2, eta = c_1 eta + c_2 Z_2

with ``step`` the deterministic scheme's step (the same compiled step as the engine's) and
a = sigma_w sqrt(h/2).  White noise: c_1 = c_2 = 0, eta = 0; coloured: a = 0, eta(0) drawn from
its stationary law N(0, sigma^2 / (2 tau)).  At sigma = 0 the kicks add exact zeros and every
state is the engine's (bitwise up to the sign of a zero).

Variates, law "gaussian" (the default): (Z_1, Z_2) of step k of path m from initial condition i
are the Box-Muller pair of one Philox4x32-10 block (numerics.philox) with counter (k, m, i, 0) and key (seed mod 2^32,
seed div 2^32) (eta(0): Z_1 of the counter (0, m, i, 1)): ``Z_1 = r cos(2 pi u_2)``,
``Z_2 = r sin(2 pi u_2)``, ``r = sqrt(-2 log u_1)``, u_1, u_2 the two 53-bit uniforms in (0, 1] of
the block (numerics.philox.uniform53), log and sqrt from wells.elementary, sin and cos of 2 pi u
by :func:`_sincos_2pi` (the same bits on every target).  A path's numbers are a pure function of
(seed, i, m, k): lanes, tasks, threads and the order of the paths cannot change them.

Law "five-point" (StepNoise.law = FIVE_POINT): Z in {0, +-sqrt 2, +-2} with probabilities 5/8, 1/8 and
1/16 each, from four random bits: its moments equal the Gaussian's through the fifth
(E Z^2 = 1, E Z^4 = 3, the odd ones 0), which is what weak order 2 needs (Kloeden & Platen 1992,
section 14.2: any variates whose first five moments match), and one Philox block (counter
(b, m, i, 2)) serves 16 steps: step k = n S + s (period n, sub-step s of S) is block
b = n ceil(S/16) + floor(s/16), byte r = s mod 16 of its words (w_0, w_1, w_2, w_3) read as one
128-bit string, Z_1 its low nibble, Z_2 its high nibble (nibble t: +sqrt 2 for t < 2, -sqrt 2 for
t < 4, +2 for t = 4, -2 for t = 5, 0 otherwise).  eta(0) stays Gaussian under either law (one
draw: its law is the stationary one, not an approximation that vanishes with h).

The lanes' machinery (:func:`_escape_task`: the variates, the refill and compaction, the period
boundary) is specialised on four numba literals: the scheme's key (as the engine's, kernels.py),
:data:`RNG_KEY`, a hash of the files inlined from outside the engine's fingerprint (this module,
numerics/philox.py, numerics/noise_loops.py, wells.elementary), the law of the variates and
whether the noise is coloured (white noise carries no eta: nothing is added to the forcing).  The
well enters only through the function pointers of its step and checks (numerics.noise_loops), so
the machinery is compiled once for every well.  :func:`_final_task` is specialised on the well's
key as well.  A kernel cached on disk is never reused after an edit of any of these files.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
from numba import literally, njit, typeof

from safebasins.core.noise_variates import VARIATES
from safebasins.core.numba_target import package_jit
from safebasins.numerics import noise_loops, philox
from safebasins.numerics.kernels import run_tasks, specialised
from safebasins.numerics.noise_loops import plus
from safebasins.numerics.scheme_code import SchemeCode, fingerprint
from safebasins.numerics.steps import coefs, row, step, wtuple
from safebasins.wells import elementary
from safebasins.wells.compiled import LLVM_INLINE, WellCode, cpu_jit, fma, mul

__all__ = ["RNG_KEY", "RNG_FILES", "MAX_STEPS", "GAUSSIAN", "FIVE_POINT", "LAWS", "StepNoise", "step_noise", "prepare",
           "escape_steps", "final_states", "gaussian_pairs", "step_variates", "check_offsets",
           "threshold_array"]

#: the noise code's files outside the engine's fingerprint (wells.elementary: its MODULE_HASH)
RNG_FILES = (__file__, philox.__file__, noise_loops.__file__)
#: the numba literal of the random-number and noise code (module docstring)
RNG_KEY = int(fingerprint(RNG_FILES)[:15], 16) ^ int(elementary.MODULE_HASH[:15], 16)
#: a path's step index is the counter's first 32-bit word
MAX_STEPS = 2 ** 32 - 1
_ZERO = np.uint64(0)
_MASK32 = philox.MASK32
_philox = cpu_jit(philox.philox4x32)
_uniform53 = cpu_jit(philox.uniform53)
#: rounds |x| < 2^51 to an integer: (x + _ROUND) - _ROUND
_ROUND = 6755399441055744.0
#: the laws of the variates (module docstring), by their names in the public API
GAUSSIAN = 0
FIVE_POINT = 1
LAWS = dict(zip(VARIATES, (GAUSSIAN, FIVE_POINT), strict=True))
_TWO = np.uint64(2)
#: five-point law: steps per Philox block (16 bytes), the nibble's width and mask
BLOCK_STEPS = 16
_U4 = np.uint64(4)
_U8 = np.uint64(8)
_U15 = np.uint64(15)
_SQRT2 = math.sqrt(2.0)


def _taylor(k: int) -> float:
    """The k-th Taylor coefficient of sin(pi r / 2) in r, (-1)^k (pi/2)^(2k+1) / (2k+1)!, from the
    double pi/2 in exact rational arithmetic, rounded once: the same constant on every machine
    (_taylor_cos: the cosine's, (-1)^k (pi/2)^(2k) / (2k)!)."""
    return float((-1) ** k * Fraction(math.pi / 2) ** (2 * k + 1) / math.factorial(2 * k + 1))


def _taylor_cos(k: int) -> float:
    return float((-1) ** k * Fraction(math.pi / 2) ** (2 * k) / math.factorial(2 * k))


# sin(pi r / 2) = r (S0 + S1 z + ... + S7 z^7), cos(pi r / 2) = C0 + C1 z + ... + C8 z^8, z = r^2,
# |r| <= 1/2 (|pi r/2| <= pi/4): truncation below 5e-17 relative
_S0, _S1, _S2, _S3, _S4, _S5, _S6, _S7 = (_taylor(k) for k in range(8))
_C0, _C1, _C2, _C3, _C4, _C5, _C6, _C7, _C8 = (_taylor_cos(k) for k in range(9))


# not cached on disk: compiled into the kernels, whose rng key hashes this file (as _gauss2)
@njit(**LLVM_INLINE)
def _sincos_2pi(u: Any) -> tuple[float, float]:
    """(sin 2 pi u, cos 2 pi u) for u in [0, 1]: 4u = n + r with n an integer and |r| <= 1/2 (r
    exact), the Taylor polynomials of sin and cos(pi r / 2), rotated by the quadrant n mod 4
    (selects, no branch: the lane loop vectorises).  A few ulps; the same operations (fma, mul)
    on every target."""
    x = mul(4.0, u)
    nf = (x + _ROUND) - _ROUND
    r = x - nf
    z = mul(r, r)
    sp = fma(fma(fma(fma(fma(fma(fma(_S7, z, _S6), z, _S5), z, _S4), z, _S3), z, _S2), z, _S1), z, _S0)
    sn = mul(r, sp)
    cs = fma(fma(fma(fma(fma(fma(fma(fma(_C8, z, _C7), z, _C6), z, _C5), z, _C4), z, _C3), z, _C2), z, _C1), z, _C0)
    # n in {0, 1, 2, 3, 4} (4: the quadrant of 0), compared as a float
    s_out = cs if nf == 1.0 else sn
    s_out = -sn if nf == 2.0 else s_out
    s_out = -cs if nf == 3.0 else s_out
    c_out = -sn if nf == 1.0 else cs
    c_out = -cs if nf == 2.0 else c_out
    c_out = sn if nf == 3.0 else c_out
    return s_out, c_out


# not cached on disk: it calls numerics.philox and wells.elementary, which the kernels' rng key hashes
@njit(**LLVM_INLINE)
def _gauss2(k0: Any, k1: Any, k: Any, m: Any, i: Any, tag: Any = _ZERO) -> tuple[float, float]:
    """The Box-Muller pair of step k of path m from initial condition i (module docstring; tag 1:
    the initial value of the coloured noise)."""
    w0, w1, w2, w3 = _philox(np.uint64(k) & _MASK32, np.uint64(m) & _MASK32, np.uint64(i) & _MASK32, tag, k0, k1)
    r = elementary.sqrt(-2.0 * elementary.log(_uniform53(w0, w1)))
    s, c = _sincos_2pi(_uniform53(w2, w3))
    return mul(r, c), mul(r, s)


# not cached on disk: compiled into the kernels, whose rng key hashes this file
@njit(**LLVM_INLINE)
def _five(t: Any) -> float:
    """The five-point variate of a nibble t in [0, 16) (module docstring; selects, no branch)."""
    z = -2.0 if t == 5 else 0.0
    z = 2.0 if t == 4 else z
    z = -_SQRT2 if t < 4 else z
    return _SQRT2 if t < 2 else z


# not cached on disk: compiled into the kernels, whose rng key hashes this file
@njit(**LLVM_INLINE)
def _five2(w: Any, r: Any) -> tuple[float, float]:
    """(Z_1, Z_2) of byte r mod 4 of the 32-bit word w: its low and high nibble."""
    x = w >> (_U8 * (np.uint64(r) & np.uint64(3)))
    return _five(x & _U15), _five((x >> _U4) & _U15)


# not cached on disk: it calls numerics.philox, which the kernels' rng key hashes
@njit(**LLVM_INLINE)
def _block(k0: Any, k1: Any, b: Any, m: Any, i: Any) -> tuple[Any, Any, Any, Any]:
    """The four words of five-point block b of path m from initial condition i."""
    return _philox(np.uint64(b) & _MASK32, np.uint64(m) & _MASK32, np.uint64(i) & _MASK32, _TWO, k0, k1)  # type: ignore[no-any-return]


_ONE = np.uint64(1)


@package_jit(cache=True, error_model="numpy")
def _pairs(rng: Any, k0: Any, k1: Any, k: Any, m: Any, i: Any) -> Any:
    literally(rng)
    n = k.shape[0]
    z = np.zeros((n, 2))
    for j in range(n):
        z[j, 0], z[j, 1] = _gauss2(k0, k1, k[j], m[j], i[j])
    return z


@package_jit(cache=True, error_model="numpy")
def _five_pairs(rng: Any, k0: Any, k1: Any, k: Any, m: Any, i: Any, S: Any) -> Any:
    literally(rng)
    n = k.shape[0]
    H = (S + BLOCK_STEPS - 1) // BLOCK_STEPS
    z = np.zeros((n, 2))
    for j in range(n):
        s = k[j] % S
        r = s % BLOCK_STEPS
        words = _block(k0, k1, (k[j] // S) * H + s // BLOCK_STEPS, m[j], i[j])
        z[j, 0], z[j, 1] = _five2(words[r // 4], r)
    return z


def gaussian_pairs(seed: int, step: np.ndarray, path: np.ndarray, ic: np.ndarray) -> np.ndarray:
    """The Gaussian pairs (Z_1, Z_2) the kernels use at (step, path, ic) (arrays of equal size,
    ints < 2^32) for ``seed``: shape (n, 2) (tests, documentation)."""
    return step_variates(seed, step, path, ic)


def step_variates(seed: int, step: np.ndarray, path: np.ndarray, ic: np.ndarray, law: int = GAUSSIAN,
                  steps_per_cycle: int = 1) -> np.ndarray:
    """The variates (Z_1, Z_2) the kernels use at (step, path, ic) (arrays of equal size, ints
    < 2^32) for ``seed`` under ``law`` (GAUSSIAN, FIVE_POINT; the five-point blocks depend on the
    steps per forcing cycle): shape (n, 2) (tests, documentation)."""
    k0, k1 = _key(seed)
    arrays = [np.ascontiguousarray(a, dtype=np.int64).ravel() for a in (step, path, ic)]
    if law == FIVE_POINT:
        return _five_pairs(RNG_KEY, k0, k1, *arrays, int(steps_per_cycle))  # type: ignore[no-any-return,call-arg]
    return _pairs(RNG_KEY, k0, k1, *arrays)  # type: ignore[no-any-return]  # (a numba dispatcher)


def _key(seed: int) -> tuple[np.uint64, np.uint64]:
    return np.uint64(seed & 0xFFFFFFFF), np.uint64(seed >> 32)


@package_jit(cache=True, nogil=True, error_model="numpy")
def _escape_task(scheme: Any, rng: Any, law: Any, coloured: Any, well: Any, steps_fn: Any, enter_fn: Any, wpar: Any,
                 task: Any, n_tasks: Any, lanes: Any, q0: Any, p0: Any, n_paths: Any, coef: Any, FS: Any, thrE2: Any,
                 lo: Any, hi: Any, cycles: Any, amp: Any, shift: Any, c1: Any, c2: Any, s_eta: Any, k0: Any, k1: Any,
                 i0: Any, m0: Any, out: Any, Q: Any, P: Any, E: Any, Z1: Any, Z2: Any, EN: Any, FIRST: Any,
                 BASE: Any) -> None:
    """Trajectories j = task, task + n_tasks, ... (path j % n_paths of initial condition
    j // n_paths): out[j * K + k] = the step after which it is first beyond the energy threshold
    thrE2[k] (sorted ascending; a barrier, a bound or a NaN state is beyond all; 0: the initial
    condition, -1: not within cycles periods).  A trajectory runs until it is beyond the largest
    threshold (then beyond all).  Lanes run one forcing period at a time; at the period
    boundary finished lanes are written out and compacted and empty lanes take the next
    trajectories (every lane is at the same sub-step of the period).  The well (its key ``well``,
    a plain integer) enters only through ``steps_fn`` and ``enter_fn``, the pointers of its step
    and checks (noise_loops); Q .. BASE: the task's lane arrays, zeros, allocated by the caller."""
    S = FS.shape[0]
    N = q0.shape[0] * n_paths
    total = np.int64(cycles) * S
    L = np.int64(lanes)
    W0 = np.zeros(L, np.uint64)          # five-point law: the words of the lane's block
    W1 = np.zeros(L, np.uint64)
    W2 = np.zeros(L, np.uint64)
    W3 = np.zeros(L, np.uint64)
    CYC = np.zeros(L, np.int64)          # the lane's periods done (BASE / S)
    H = (S + BLOCK_STEPS - 1) // BLOCK_STEPS      # five-point blocks per period
    IC = np.zeros(L, np.int64)
    PATH = np.zeros(L, np.int64)
    J = np.zeros(L, np.int64)
    K = thrE2.shape[0]
    FL = FIRST[K - 1]                    # (beyond the largest: beyond all, the trajectory is done)
    nxt = np.int64(task)
    nact = np.int64(0)
    while True:
        k = np.int64(0)
        for l in range(nact):
            if FL[l] >= 0 or BASE[l] >= total:
                for r in range(K):
                    out[J[l] * K + r] = FIRST[r, l]
            else:
                Q[k] = Q[l]
                P[k] = P[l]
                E[k] = E[l]
                IC[k] = IC[l]
                PATH[k] = PATH[l]
                J[k] = J[l]
                BASE[k] = BASE[l]
                CYC[k] = CYC[l]
                for r in range(K):
                    FIRST[r, k] = FIRST[r, l]
                k += 1
        nact = k
        while nact < L and nxt < N:
            j = nxt
            nxt += n_tasks
            i = j // n_paths
            q = q0[i]
            p = p0[i]
            enter_fn(scheme, well, rng, wpar, q, p, thrE2, lo, hi, FIRST, nact)
            if FL[nact] >= 0 or total == 0:
                for r in range(K):
                    out[j * K + r] = FIRST[r, nact]
                continue
            Q[nact] = q
            P[nact] = p
            PATH[nact] = j - i * n_paths + m0
            IC[nact] = i + i0
            E[nact] = mul(s_eta, _gauss2(k0, k1, 0, PATH[nact], IC[nact], _ONE)[0])
            J[nact] = j
            BASE[nact] = 0
            CYC[nact] = 0
            nact += 1
        if nact == 0:
            break
        for s in range(S):
            # the variates in a lane loop of their own; the well's step and checks (noise_loops)
            if law == GAUSSIAN:
                for l in range(nact):
                    Z1[l], Z2[l] = _gauss2(k0, k1, BASE[l] + s, PATH[l], IC[l])
            else:
                r = s % BLOCK_STEPS
                if r == 0:
                    b = s // BLOCK_STEPS
                    for l in range(nact):
                        W0[l], W1[l], W2[l], W3[l] = _block(k0, k1, CYC[l] * H + b, PATH[l], IC[l])
                W = W0 if r < 4 else (W1 if r < 8 else (W2 if r < 12 else W3))
                for l in range(nact):
                    Z1[l], Z2[l] = _five2(W[l], r)
            steps_fn(scheme, well, rng, coloured, wpar, nact, s, Q, P, E, Z1, Z2, EN, FIRST, BASE, coef, FS, thrE2,
                     lo, hi, amp, shift, c1, c2)
        for l in range(nact):
            BASE[l] += S
            CYC[l] += 1


@package_jit(cache=True, nogil=True, error_model="numpy")
def _final_task(well: Any, scheme: Any, rng: Any, law: Any, coloured: Any, wpar: Any, task: Any, n_tasks: Any, q0: Any,
                p0: Any, n_paths: Any, coef: Any, FS: Any, n_steps: Any, amp: Any, c1: Any, c2: Any, s_eta: Any,
                k0: Any, k1: Any, i0: Any, m0: Any, qo: Any, po: Any, eo: Any) -> None:
    """Plain integration (no escape) of trajectories j = task, task + n_tasks, ... for n_steps
    steps; the same step as _escape_task."""
    S = FS.shape[0]
    w = wtuple(wpar)
    c = coefs(scheme, coef[0])
    N = q0.shape[0] * n_paths
    H = (S + BLOCK_STEPS - 1) // BLOCK_STEPS
    for j in range(task, N, n_tasks):
        r = j // n_paths
        m = j - r * n_paths + m0
        i = r + i0
        q = q0[r]
        p = p0[r]
        e = mul(s_eta, _gauss2(k0, k1, 0, m, i, _ONE)[0])
        words = (_ZERO, _ZERO, _ZERO, _ZERO)
        for n in range(n_steps):
            s = n % S
            if law == GAUSSIAN:
                z1, z2 = _gauss2(k0, k1, n, m, i)
            else:
                r = s % BLOCK_STEPS
                if r == 0:
                    words = _block(k0, k1, (n // S) * H + s // BLOCK_STEPS, m, i)
                z1, z2 = _five2(words[r // 4], r)
            f = row(scheme, FS, s)
            if coloured:
                e = fma(c2, z1, mul(c1, e))
                q, p = step(scheme, well, w, q, fma(amp, z1, p), c, plus(f, e))
                e = fma(c2, z2, mul(c1, e))
            else:
                q, p = step(scheme, well, w, q, fma(amp, z1, p), c, f)
            p = fma(amp, z2, p)
        qo[j] = q
        po[j] = p
        eo[j] = e


@dataclass(frozen=True)
class StepNoise:
    """The noise coefficients of one step (module docstring): the white half kick ``amp`` =
    sigma sqrt(h/2), the Ornstein-Uhlenbeck half step ``eta = c1 eta + c2 Z`` and ``s_eta``, the
    standard deviation of eta's stationary law (eta(0) = s_eta Z); ``law`` the variates' law
    (GAUSSIAN or FIVE_POINT)."""

    amp: float
    c1: float = 0.0
    c2: float = 0.0
    s_eta: float = 0.0
    law: int = GAUSSIAN

    @property
    def coloured(self) -> bool:
        """Whether the step carries an Ornstein-Uhlenbeck force (else eta = 0 and is not computed)."""
        return bool(self.c1 != 0.0 or self.c2 != 0.0 or self.s_eta != 0.0)


def step_noise(sigma: float, h: float, noise_time: float = 0.0, law: int = GAUSSIAN) -> StepNoise:
    """The coefficients of a step h for white noise of amplitude sigma (noise_time = 0) or an
    Ornstein-Uhlenbeck force d eta = -(eta / tau) dt + (sigma / tau) dW of correlation time
    tau = noise_time > 0 (the same integrated intensity: int <eta(0) eta(t)> dt = sigma^2), with
    variates of ``law``."""
    if law not in LAWS.values():
        raise ValueError(f"law must be one of {sorted(LAWS.values())} ({', '.join(LAWS)}), got {law!r}")
    if noise_time == 0.0:
        return StepNoise(sigma * math.sqrt(0.5 * h), law=law)
    x = h / noise_time
    return StepNoise(0.0, math.exp(-0.5 * x), sigma * math.sqrt(-math.expm1(-x) / (2.0 * noise_time)),
                     sigma / math.sqrt(2.0 * noise_time), law)


def threshold_array(thrE2: float | np.ndarray) -> np.ndarray:
    """The energy thresholds 2 xi_max as a contiguous float64 array: ValueError naming thrE2 unless
    they are a scalar or a non-empty 1-D array, ascending, without NaN."""
    thr = np.ascontiguousarray(np.atleast_1d(np.asarray(thrE2, dtype=float)))
    if thr.ndim != 1 or thr.size == 0 or np.isnan(thr).any() or (np.diff(thr) < 0).any():
        raise ValueError(f"thrE2 must be a scalar or a non-empty ascending 1-D array without NaN, got {thrE2!r}")
    return thr


def check_offsets(offsets: tuple[int, int], n_ic: int, n_paths: int) -> None:
    """ValueError naming ``ic_offset`` or ``path_offset`` unless each is an integer >= 0 and the
    counter words it starts (n_ic initial conditions, n_paths paths) stay below 2^32."""
    for what, offset, count in (("ic_offset", offsets[0], n_ic), ("path_offset", offsets[1], n_paths)):
        if isinstance(offset, bool) or not isinstance(offset, (int, np.integer)) or offset < 0:
            raise ValueError(f"{what} must be a non-negative integer, got {offset!r}")
        if offset + count > 2 ** 32:
            raise ValueError(f"{what}: {offset} + {count} exceeds 2^32 (a word of the random counter)")


def prepare(code: WellCode, scheme: SchemeCode, q0: np.ndarray, coef: np.ndarray, sintab: np.ndarray, F: float,
            seed: int, n_steps: int, name: str = "cycles", n_paths: int = 1, offsets: tuple[int, int] = (0, 0)
            ) -> tuple[np.ndarray, np.ndarray, np.uint64, np.uint64]:
    """The checks of every backend's arguments (as :func:`escape_steps`; n_steps: the steps of a
    path, set by the argument ``name``) and what they share: (q0 as float64, the forcing products
    F * sintab, the Philox key)."""
    check_offsets(offsets, int(np.size(q0)), n_paths)
    if n_steps > MAX_STEPS:
        raise ValueError(f"{name}: {n_steps} steps per path exceed {MAX_STEPS} (the random counter's range)")
    if coef.ndim != 2 or coef.shape != (1, scheme.n_coef):
        raise ValueError(f"coef must be one row of lane_coefficients of {scheme.name}, got shape {coef.shape}")
    if sintab.ndim != 2 or sintab.shape[1] != scheme.width:
        raise ValueError(f"the forcing table of {scheme.name} has {scheme.width} columns, got shape {sintab.shape}")
    if not 0 <= seed < 2 ** 64:
        raise ValueError(f"seed must be an integer in [0, 2^64), got {seed}")
    k0, k1 = _key(int(seed))
    return np.ascontiguousarray(q0, dtype=float), np.ascontiguousarray(F * sintab), k0, k1


def escape_steps(code: WellCode, scheme: SchemeCode, q0: np.ndarray, p0: np.ndarray, n_paths: int, coef: np.ndarray,
                 sintab: np.ndarray, F: float, thrE2: float | np.ndarray, cycles: int, noise: StepNoise, seed: int, *,
                 shift: float = 0.0, bounds: tuple[float, float] = (-math.inf, math.inf),
                 wpar: np.ndarray | None = None, n_tasks: int = 1, lanes: int = 256, ic_offset: int = 0,
                 path_offset: int = 0) -> np.ndarray:
    """First steps beyond the thresholds of ``n_paths`` paths from every initial condition,
    shape (len(q0), n_paths), int64 (0: the initial condition is beyond, -1: not within
    ``cycles`` periods of ``sintab.shape[0]`` steps); for an array thrE2 of K energy thresholds
    (ascending), shape (len(q0), n_paths, K), from one pass.  code, scheme: the compiled well and
    scheme (damped variant for beta > 0); coef: their lane_coefficients (one row); sintab: the
    forcing table (schemes.sine_table), times F; thrE2 = 2 xi_max (a float or an ascending array);
    noise: the step's noise coefficients (:func:`step_noise`); shift: the energy boundary shift per
    ``|p|`` (module docstring); bounds: a displacement pair (lo, hi); wpar: the well's wpar (None:
    code.wpar; the barriers are its first two entries); ic_offset, path_offset: the index of the
    first initial condition and of the first path in the random counters (a chunk of a larger
    ensemble draws that ensemble's streams).  The result does not
    depend on n_tasks or lanes."""
    q, FS, k0, k1 = prepare(code, scheme, q0, coef, sintab, F, seed, int(cycles) * sintab.shape[0],
                            n_paths=int(n_paths), offsets=(ic_offset, path_offset))
    p = np.ascontiguousarray(p0, dtype=float)
    thr = threshold_array(thrE2)
    out = np.full(q.size * int(n_paths) * thr.size, -1, np.int64)
    wp = code.wpar if wpar is None else np.ascontiguousarray(wpar, dtype=float)
    coef = np.ascontiguousarray(coef)
    L = int(lanes)
    # each task's lanes: (q, p, eta, Z1, Z2, checked energy), first steps beyond, steps done
    work = [(*np.zeros((6, L)), np.zeros((thr.size, L), np.int64), np.zeros(L, np.int64)) for _ in range(n_tasks)]
    lane, FIRST, BASE = typeof(work[0][0]), typeof(work[0][6]), typeof(work[0][7])
    calls = [noise_loops.steps_pointer(scheme.key, code.key, RNG_KEY, noise.coloured, typeof(wp), lane, FIRST, BASE,
                                       typeof(coef), typeof(FS), typeof(thr)),
             noise_loops.enter_pointer(scheme.key, code.key, RNG_KEY, typeof(wp), typeof(thr), FIRST)]
    args = [scheme.key, RNG_KEY, int(noise.law), noise.coloured, code.key, *calls, wp, 0, int(n_tasks), L, q, p,
            int(n_paths), coef, FS, thr, float(bounds[0]), float(bounds[1]), int(cycles), float(noise.amp),
            float(shift), float(noise.c1), float(noise.c2), float(noise.s_eta), k0, k1, int(ic_offset),
            int(path_offset), out]
    entry = specialised(_escape_task, [*args, *work[0]], n_literal=4)
    run_tasks(lambda task: entry(*args[:8], task, *args[9:], *work[task]), int(n_tasks))
    return out.reshape(q.size, int(n_paths)) if np.ndim(thrE2) == 0 else out.reshape(q.size, int(n_paths), thr.size)


def final_states(code: WellCode, scheme: SchemeCode, q0: np.ndarray, p0: np.ndarray, n_paths: int, coef: np.ndarray,
                 sintab: np.ndarray, F: float, n_steps: int, noise: StepNoise, seed: int, n_tasks: int = 1,
                 ic_offset: int = 0, path_offset: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, p, eta) of every path after ``n_steps`` steps, shape (len(q0), n_paths) each, no escape
    checks (weak-order tests, benchmarks); arguments as :func:`escape_steps`."""
    q, FS, k0, k1 = prepare(code, scheme, q0, coef, sintab, F, seed, int(n_steps), "n_steps", int(n_paths),
                            (ic_offset, path_offset))
    p = np.ascontiguousarray(p0, dtype=float)
    qo = np.empty(q.size * int(n_paths))
    po = np.empty_like(qo)
    eo = np.empty_like(qo)
    args = [code.key, scheme.key, RNG_KEY, int(noise.law), noise.coloured, code.wpar, 0, int(n_tasks), q, p,
            int(n_paths),
            np.ascontiguousarray(coef),
            FS, int(n_steps), float(noise.amp), float(noise.c1), float(noise.c2), float(noise.s_eta), k0, k1,
            int(ic_offset), int(path_offset), qo, po, eo]
    entry = specialised(_final_task, args, n_literal=5)
    run_tasks(lambda task: entry(*args[:6], task, *args[7:]), int(n_tasks))
    shape = (q.size, int(n_paths))
    return qo.reshape(shape), po.reshape(shape), eo.reshape(shape)
