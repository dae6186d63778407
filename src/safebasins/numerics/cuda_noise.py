"""The CUDA backend of the noisy escape ensemble: the GPU twin of noise_kernels.escape_steps.

:func:`escape_steps` takes the arguments of noise_kernels.escape_steps (checked by the same
noise_kernels.prepare) and returns the same first steps beyond the thresholds, bitwise: each
trajectory (initial condition i, path m) runs the CPU lanes' sequence of IEEE operations,

    eta(0) = s_eta Z_1(0, m, i, tag 1);  per step n: (Z_1, Z_2) = Box-Muller of Philox (n, m, i, 0)
    (five-point law: the nibbles of the step's byte of block (b, m, i, 2), noise_kernels),
    eta = c1 eta + c2 Z_1, p += a Z_1, (q, p) = step(q, p; F sin + eta), p += a Z_2, eta = c1 eta + c2 Z_2,
    escape when 2 H0 + shift ``|p|`` > 2 xi_max, q beyond a barrier or a bound (a NaN state included)

with every product that meets an add an explicit fma or a mul (wells.compiled.mul: never
contracted), as cuda_kernels explains for the deterministic engine.

One source, two targets: nothing of the arithmetic is written here.  The well's force and energy
(wells.compiled.WellCode.make) and the scheme's step (scheme_code.SchemeCode.make) are compiled as
device functions as in cuda_kernels; the Gaussian pair, the sine and cosine of 2 pi u, the escape
test and the forcing-plus-noise tuple are noise_kernels' own Python source (the numba functions'
``py_func``), compiled again with their globals bound to device functions (Philox and its uniforms
from numerics.philox, log and sqrt from wells.elementary.cuda_device), the way
wells.elementary_targets.compile_code compiles one source per target.  Under numba's CUDA
simulator (NUMBA_ENABLE_CUDASIM=1) the device functions run as that Python, with the CPU's
correctly rounded fma: tests/numerics/test_cuda_simulator_noise.py compares the escape steps
with the CPU lanes'.

Kernel: one thread per trajectory at a time; a thread whose trajectory escaped (or reached the
horizon) takes the next one from a global atomic counter, so threads stay busy until the queue is
empty whatever the escape times (no period boundaries to wait for: the forcing table, small, is
read from global memory, where each thread reads the row of its own sub-step).  Which thread runs
a trajectory cannot change its numbers: they are a pure function of (seed, i, m, step).
"""
from __future__ import annotations

import functools
import time
from collections.abc import Callable
from types import FunctionType, ModuleType, SimpleNamespace
from typing import Any

import numpy as np
from numba import cuda, types, uint64

from safebasins.core import checks
from safebasins.numerics import cuda_engine, cuda_kernels, noise_kernels, noise_loops, philox
from safebasins.numerics.scheme_code import SchemeCode, code_of_scheme
from safebasins.numerics.steps import Floats, Int, Ints
from safebasins.wells import elementary
from safebasins.wells.compiled import WellCode, code_of, fma, mul

__all__ = ["escape_steps", "noise_kernel"]

_ONE = np.uint64(1)
_ZERO = np.uint64(0)
#: threads per block and blocks under the simulator: it runs every thread as a Python thread
#: and polls them all from the launching thread, so few threads, each taking many trajectories
SIMULATOR_BLOCK = 4
SIMULATOR_GRID = 1


def _device(fn: Callable[..., Any]) -> Any:
    return cuda.jit(device=True)(fn)


def _retarget(dispatcher: Any, **rebind: Any) -> Any:
    """The device function of a CPU numba function's Python source (``dispatcher.py_func``), its
    globals named in ``rebind`` bound to the given (device) objects."""
    f = dispatcher.py_func
    g = FunctionType(f.__code__, {**f.__globals__, **rebind}, f.__name__, f.__defaults__, f.__closure__)
    g.__qualname__, g.__doc__ = f.__qualname__, f.__doc__
    return _device(g)


def _as_module(ns: SimpleNamespace, name: str) -> ModuleType:
    """A module holding the attributes of ``ns``: code that calls ``elementary.log(x)`` resolves the
    attribute at compile time, as for the real module."""
    mod = ModuleType(name)
    mod.__dict__.update(vars(ns))
    return mod


@functools.cache
def _philox_device() -> Any:
    return _device(philox.philox4x32)


@functools.cache
def _five_point() -> tuple[Any, Any]:
    """noise_kernels._block and _five2 as device functions: a five-point block's words and the
    variates of one byte."""
    five = _retarget(noise_kernels._five)
    return (_retarget(noise_kernels._block, _philox=_philox_device()), _retarget(noise_kernels._five2, _five=five))


@functools.cache
def _gauss2() -> Any:
    """noise_kernels._gauss2 as a device function: the Box-Muller pair of one Philox block."""
    el = _as_module(elementary.cuda_device(), "safebasins.wells.elementary.cuda_device")
    sincos = _retarget(noise_kernels._sincos_2pi)
    return _retarget(noise_kernels._gauss2, _philox=_philox_device(), _uniform53=_device(philox.uniform53),
                     _sincos_2pi=sincos, elementary=el)


def _constant(value: bool) -> Any:
    def const(well: Int) -> bool:
        return value
    return _device(const)


@functools.cache
def noise_kernel(well_key: int, scheme_key: int, law: int = noise_kernels.GAUSSIAN, coloured: bool = True) -> Any:
    """The compiled kernel of the noisy ensemble for a compiled well and scheme (their keys:
    wells.compiled.WellCode.key, scheme_code.SchemeCode.key), a law of the variates
    (noise_kernels.GAUSSIAN, FIVE_POINT) and white or coloured noise (white: no eta is carried or
    added, as on the CPU lanes); cached per combination.

    Launch: kernel[grid, block](q0, p0, n_paths, coef, FS, SW, total, thrE2, lo, hi, amp, shift, c1,
    c2, s_eta, k0, k1, i0, m0, wpar, counter, out): q0, p0 (n_ic,) float64; coef (NC,) the scheme's
    coefficients (lane_coefficients, one row); FS (S * W,) the forcing products F * sine_table,
    flat; SW = S * W (uint64); total = cycles * S steps; thrE2 (K,) the energy thresholds 2 xi_max,
    ascending; (lo, hi) a displacement
    pair; amp, shift, c1, c2, s_eta: noise_kernels.StepNoise and the energy shift; (k0, k1) the
    Philox key; (i0, m0) the counters' offsets of the initial condition and the path; wpar the
    well's (steps.N_WPAR,); counter (1,) int64 = 0; out (n_ic * n_paths * K,) int64, -1 on entry:
    trajectory j = i * n_paths + m gets its first step beyond threshold k in out[j * K + k] (0: the
    initial condition, -1: none within total steps)."""
    code: WellCode = code_of(well_key)
    sc: SchemeCode = code_of_scheme(scheme_key)
    force, energy_w = code.make(_device)
    step = sc.make(_device, force)
    H = sc.helpers(_device)
    flat_row, flat_coefs = H["flat_row"], H["flat_coefs"]
    plus = _device(noise_loops._ol_plus(types.UniTuple(types.float64, sc.width), types.float64))
    beyond = _retarget(noise_loops.beyond, abs_tracking=_constant(code.abs_tracking))
    gauss2 = _gauss2()
    block, five2 = _five_point()
    UW = np.uint64(sc.width)
    gaussian = law == noise_kernels.GAUSSIAN
    BS = noise_kernels.BLOCK_STEPS

    def noisy(q0: Floats, p0: Floats, n_paths: Int, coef: Floats, FS: Floats, SW: np.uint64, total: Int,
              thrE2: Floats, lo: float, hi: float, amp: float, shift: float, c1: float, c2: float, s_eta: float,
              k0: np.uint64, k1: np.uint64, i0: Int, m0: Int, wpar: Floats, counter: Ints, out: Ints) -> None:
        w = (wpar[2], wpar[3], wpar[4], wpar[5], wpar[6], wpar[7], wpar[8],
             wpar[9], wpar[10], wpar[11], wpar[12], wpar[13], wpar[14], wpar[15])
        c = flat_coefs(coef, uint64(0))
        N = q0.shape[0] * n_paths
        K = thrE2.shape[0]
        S = SW // UW
        H = (S + BS - 1) // BS
        while True:
            j = cuda.atomic.add(counter, 0, 1)
            if j >= N:
                break
            r = j // n_paths
            m = j - r * n_paths + m0
            i = r + i0
            q = q0[r]
            p = p0[r]
            # beyond threshold k implies beyond every lower one (ascending): the next one is watched
            e0 = energy_w(w, q, p)
            nx = 0
            while nx < K and beyond(0, wpar, q, e0, thrE2[nx], lo, hi):
                out[j * K + nx] = 0
                nx += 1
            if nx == K:
                continue
            e = mul(s_eta, gauss2(k0, k1, 0, m, i, _ONE)[0])
            o = uint64(0)
            s = uint64(0)                      # the sub-step of the period, and the period
            cyc = uint64(0)
            words = (_ZERO, _ZERO, _ZERO, _ZERO)
            for n in range(total):
                if gaussian:
                    z1, z2 = gauss2(k0, k1, n, m, i, _ZERO)
                else:
                    r = s % BS
                    if r == 0:
                        words = block(k0, k1, cyc * H + s // BS, m, i)
                    z1, z2 = five2(words[r // 4], r)
                if coloured:
                    eta = fma(c2, z1, mul(c1, e))
                    q, p = step(w, q, fma(amp, z1, p), c, plus(flat_row(FS, o), eta))
                    e = fma(c2, z2, mul(c1, eta))
                else:
                    q, p = step(w, q, fma(amp, z1, p), c, flat_row(FS, o))
                p = fma(amp, z2, p)
                en = fma(shift, abs(p), energy_w(w, q, p))
                while nx < K and beyond(0, wpar, q, en, thrE2[nx], lo, hi):
                    out[j * K + nx] = n + 1
                    nx += 1
                if nx == K:
                    break
                o += UW
                s += uint64(1)
                if o == SW:
                    o = uint64(0)
                    s = uint64(0)
                    cyc += uint64(1)

    sig = ("void(float64[::1], float64[::1], int64, float64[::1], float64[::1], uint64, int64, float64[::1], float64, "
           "float64, float64, float64, float64, float64, float64, uint64, uint64, int64, int64, float64[::1], "
           "int64[::1], int64[::1])")
    return cuda.jit(sig)(noisy)


def escape_steps(code: WellCode, scheme: SchemeCode, q0: np.ndarray, p0: np.ndarray, n_paths: int, coef: np.ndarray,
                 sintab: np.ndarray, F: float, thrE2: float | np.ndarray, cycles: int, noise: noise_kernels.StepNoise,
                 seed: int, *, shift: float = 0.0, bounds: tuple[float, float] = (-np.inf, np.inf),
                 wpar: np.ndarray | None = None, block: int | None = None, grid: int | None = None,
                 timing: dict[str, Any] | None = None, ic_offset: int = 0, path_offset: int = 0) -> np.ndarray:
    """noise_kernels.escape_steps on the GPU (the same arguments and result, bitwise): first steps
    beyond the thresholds, shape (len(q0), n_paths), int64 (an array thrE2 of K thresholds: shape
    (len(q0), n_paths, K)).

    block, grid: threads per block (default 128, the simulator 4) and blocks (default: as many as
    stay resident, the simulator 1); the result does not depend on them.  timing: a dict to
    receive kernel_s (CUDA events; the simulator: host clock), grid, block.  RuntimeError without
    a CUDA GPU or the simulator (cuda_engine.require_cuda)."""
    cuda_engine.require_cuda()
    total = int(cycles) * sintab.shape[0]
    q, FS, k0, k1 = noise_kernels.prepare(code, scheme, q0, coef, sintab, F, seed, total, n_paths=int(n_paths),
                                          offsets=(ic_offset, path_offset))
    p = np.ascontiguousarray(p0, dtype=float)
    thr = noise_kernels.threshold_array(thrE2)
    N = q.size * int(n_paths)
    out = np.full(N * thr.size, -1, np.int64)
    if N:
        blk = (checks.check_positive_int("block", block) if block is not None else
               (SIMULATOR_BLOCK if cuda_kernels.SIMULATOR else cuda_kernels.BLOCK))
        kernel = noise_kernel(code.key, scheme.key, noise.law, noise.coloured)
        nblk = (checks.check_positive_int("grid", grid) if grid is not None else
                SIMULATOR_GRID if cuda_kernels.SIMULATOR else cuda_engine.launch_grid(kernel, N, blk, 0))
        wp = code.wpar if wpar is None else np.ascontiguousarray(wpar, dtype=float)
        d_out = cuda.to_device(out)
        args = (cuda.to_device(q), cuda.to_device(p), int(n_paths), cuda.to_device(np.ascontiguousarray(coef).ravel()),
                cuda.to_device(FS.ravel()), np.uint64(FS.size), total, cuda.to_device(thr), float(bounds[0]),
                float(bounds[1]), float(noise.amp), float(shift), float(noise.c1), float(noise.c2), float(noise.s_eta),
                k0, k1, int(ic_offset), int(path_offset), cuda.to_device(wp), cuda.to_device(np.zeros(1, np.int64)),
                d_out)
        if cuda_kernels.SIMULATOR:
            t0 = time.perf_counter()
            kernel[nblk, blk](*args)
            kernel_s = time.perf_counter() - t0
        else:
            start, end = cuda.event(), cuda.event()
            start.record()
            kernel[nblk, blk](*args)
            end.record()
            end.synchronize()
            kernel_s = cuda.event_elapsed_time(start, end) / 1e3
        out = d_out.copy_to_host()
        if timing is not None:
            timing.update(kernel_s=kernel_s, grid=nblk, block=blk)
    return out.reshape(q.size, int(n_paths)) if np.ndim(thrE2) == 0 else out.reshape(q.size, int(n_paths), thr.size)
