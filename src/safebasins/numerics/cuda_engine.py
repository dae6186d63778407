"""Python driver of the CUDA ensemble kernel: the GPU twin of engine.run_ensemble.

run_ensemble_cuda takes the arguments of engine.run_ensemble (less threads and store) and
returns the same (steps_E, steps_Q), bitwise: every trajectory runs the same IEEE operations
as on the CPU (see cuda_kernels for how contraction is kept out), so the first-crossing steps
are identical, whatever the grid, block or lane a trajectory ran in.

It needs a CUDA GPU, or numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1 set before numba.cuda
is first imported; slow, for tests).  Without either it raises RuntimeError: there is no
silent fallback to the CPU (the caller picks the backend).
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import cuda

from safebasins.numerics import cuda_kernels
from safebasins.numerics import engine
from safebasins.numerics import kernels

SIMULATOR_BLOCK = 32      # threads per block under the simulator (one Python thread each)
SIMULATOR_GRID = 2        # blocks under the simulator (run one after the other)
SIMULATOR_WARP = 8        # compaction granularity under the simulator: small, so tests exercise it
GOLDEN = 0.6180339887498949


def cuda_available():
    """True when run_ensemble_cuda can run: a usable CUDA GPU (driver and NVVM), or the simulator."""
    if cuda_kernels.SIMULATOR:
        return True
    return bool(cuda.is_available())


def require_cuda():
    if not cuda_available():
        raise RuntimeError(
            "the CUDA backend needs a CUDA GPU (driver and NVVM found by numba-cuda) or numba's CUDA "
            "simulator (set NUMBA_ENABLE_CUDASIM=1 before numba.cuda is imported); neither is available "
            "here: use the CPU backend")


def scramble_multiplier(n):
    """A multiplier coprime to n near n / golden ratio: c -> c * A mod n is a permutation of
    range(n) that spreads neighbouring indices (clustered escape times in an IC grid) evenly
    over the grid's blocks.  c * A < n^2 must fit in int64: n < 3e9."""
    if n <= 2:
        return 1
    a = max(1, int(round(n * GOLDEN)))
    while math.gcd(a, n) != 1:
        a += 1
    return a


def _positive_int(name, value):
    if isinstance(value, (float, np.floating)) and float(value).is_integer():
        value = int(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def launch_grid(kernel, n, block, smem):
    """Blocks to launch: no more than the GPU keeps resident (persistent threads take the
    remaining trajectories from the queue), no more than the work needs."""
    need = max(1, math.ceil(n / block))
    if cuda_kernels.SIMULATOR:
        return min(need, SIMULATOR_GRID)
    overload = next(iter(kernel.overloads.values()))
    return max(1, min(need, overload.max_cooperative_grid_blocks(block, smem)))


def run_ensemble_cuda(q0, p0, pidx, Omega, F, Psi, *, xi_max=(), q_max=(), q_bounds=(), cycles, steps_per_cycle,
                      stop_any=False, integrator="srkn6b", well=None, damping=0.0, block=None, grid=None,
                      timing=None):
    """Integrate trajectories i from (q0[i], p0[i]) with Omega[pidx[i]], F[pidx[i]] on the GPU.

    Returns (steps_E (N, nE), steps_Q (N, nQ)): int64 step of first crossing of each threshold,
    in the order given (-1: not within `cycles` periods, 0: the initial condition is beyond),
    bitwise equal to engine.run_ensemble's; the displacement columns are the q_max thresholds
    then the q_bounds pairs (nested: engine.displacement_pairs).  A trajectory stops once every
    threshold is crossed (stop_any: once any is).  integrator: "srkn6b" (default) or "rk4";
    well: any form safebasins.wells.resolve_well reads (None: the quartic), its compiled form as
    on the CPU; damping: beta >= 0, the scheme's damped variant for beta > 0 (as on the CPU).

    block, grid: threads per block (default 128, simulator 32) and blocks (default: as many as
    stay resident; the simulator: 2); results do not depend on them.  timing: a dict to receive
    kernel_s (CUDA events around the kernel; the simulator: host clock), wall_s (transfers,
    launch and kernel), grid, block, shared_table, regs_per_thread (GPU only).
    """
    require_cuda()
    kernels.check_integrator(integrator)
    code = engine.engine_code(well, q_max, q_bounds)
    t_wall = time.perf_counter()
    q0 = np.ascontiguousarray(q0, dtype=float).ravel()
    p0 = np.ascontiguousarray(p0, dtype=float).ravel()
    pidx = np.ascontiguousarray(pidx, dtype=np.int64).ravel()
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float)).ravel()
    F = np.atleast_1d(np.asarray(F, dtype=float)).ravel()
    xi = np.asarray(xi_max, dtype=float).ravel()
    lo, hi, oQ, _ = engine.displacement_pairs(q_max, q_bounds)
    N = q0.size
    if p0.size != N or pidx.size != N:
        raise ValueError(f"q0, p0 and pidx must have the same size, got {q0.size}, {p0.size}, {pidx.size}")
    if Omega.size != F.size:
        raise ValueError(f"Omega and F must have one value per parameter set, got sizes {Omega.size} and {F.size}")
    if N and (pidx.min() < 0 or pidx.max() >= Omega.size):
        raise ValueError(f"pidx must index the {Omega.size} parameter set(s)")
    cycles = _positive_int("cycles", cycles)
    S = _positive_int("steps_per_cycle", steps_per_cycle)
    nE, nQ = xi.size, hi.size
    oE = np.argsort(xi, kind="stable")
    outE = np.full((N, nE), -1, dtype=np.int64)
    outQ = np.full((N, nQ), -1, dtype=np.int64)
    if N:
        # the host forms every product the CPU forms outside an fma (cuda_kernels docstring)
        coef = np.ascontiguousarray(kernels.lane_coefficients(Omega, S, integrator, damping)).ravel()
        sintab = kernels.sine_table(S, Psi, integrator)
        FS = np.ascontiguousarray(F[:, None, None] * sintab[None, :, :]).ravel()
        thrE2 = np.zeros(max(nE, 1))
        thrE2[:nE] = 2.0 * xi[oE]
        thrHi = np.zeros(max(nQ, 1))
        thrHi[:nQ] = hi[oQ]
        thrLo = np.zeros(max(nQ, 1))
        thrLo[:nQ] = lo[oQ]
        blk = int(block) if block is not None else (SIMULATOR_BLOCK if cuda_kernels.SIMULATOR else cuda_kernels.BLOCK)
        shared = FS.nbytes <= cuda_kernels.SHARED_TABLE_BYTES
        smem = FS.nbytes if shared else 0
        warp = SIMULATOR_WARP if cuda_kernels.SIMULATOR else cuda_kernels.WARP
        kernel = cuda_kernels.ensemble_kernel(integrator, shared, blk, math.gcd(blk, warp), code, damping > 0)
        nblk = int(grid) if grid is not None else launch_grid(kernel, N, blk, smem)

        d_outE = cuda.to_device(np.full(max(N * nE, 1), -1, dtype=np.int64))
        d_outQ = cuda.to_device(np.full(max(N * nQ, 1), -1, dtype=np.int64))
        args = (cuda.to_device(q0), cuda.to_device(p0), cuda.to_device(pidx), cuda.to_device(coef),
                cuda.to_device(FS), cuda.to_device(thrE2), nE, cuda.to_device(thrLo), cuda.to_device(thrHi), nQ, N, S,
                cycles, bool(stop_any), scramble_multiplier(N), cuda.to_device(np.zeros(1, np.int64)), d_outE, d_outQ,
                cuda.to_device(code.wpar))
        if cuda_kernels.SIMULATOR:
            t0 = time.perf_counter()
            kernel[nblk, blk, 0, smem](*args)
            kernel_s = time.perf_counter() - t0
        else:
            start, end = cuda.event(), cuda.event()
            start.record()
            kernel[nblk, blk, 0, smem](*args)
            end.record()
            end.synchronize()
            kernel_s = cuda.event_elapsed_time(start, end) / 1e3
        outE[:] = d_outE.copy_to_host()[:N * nE].reshape(N, nE)
        outQ[:] = d_outQ.copy_to_host()[:N * nQ].reshape(N, nQ)
        if timing is not None:
            timing.update(kernel_s=kernel_s, grid=nblk, block=blk, shared_table=shared)
            if not cuda_kernels.SIMULATOR:
                timing["regs_per_thread"] = next(iter(kernel.overloads.values())).regs_per_thread
    # back to the caller's threshold order
    steps_E = np.empty_like(outE)
    steps_E[:, oE] = outE
    steps_Q = np.empty_like(outQ)
    steps_Q[:, oQ] = outQ
    if timing is not None:
        timing["wall_s"] = time.perf_counter() - t_wall
    return steps_E, steps_Q
