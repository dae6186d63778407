"""The CUDA backend of the ensemble engine: the GPU twin of engine.run_cpu.

run_cuda takes the same checked problem (problem.EnsembleProblem) as the CPU backend and
returns the same (steps_E, steps_Q), bitwise: every trajectory runs the same IEEE operations
as on the CPU (see cuda_kernels for how contraction is kept out), so the first-crossing steps
are identical, whatever the grid, block or lane a trajectory ran in.  engine.integrate is the
one entry point of both.

It needs a CUDA GPU, or numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1 set before numba.cuda
is first imported; slow, for tests).  Without either it raises RuntimeError: there is no
silent fallback to the CPU (the caller picks the backend).
"""
from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from numba import cuda

from safebasins.core import checks
from safebasins.numerics import cuda_kernels
from safebasins.numerics.problem import EnsembleProblem

SIMULATOR_BLOCK = 32      # threads per block under the simulator (one Python thread each)
SIMULATOR_GRID = 2        # blocks under the simulator (run one after the other)
SIMULATOR_WARP = 8        # compaction granularity under the simulator: small, so tests exercise it
GOLDEN = 0.6180339887498949


def cuda_available() -> bool:
    """True when run_cuda can run: a usable CUDA GPU (driver and NVVM), or the simulator."""
    if cuda_kernels.SIMULATOR:
        return True
    return bool(cuda.is_available())


def require_cuda() -> None:
    if not cuda_available():
        raise RuntimeError(
            "the CUDA backend needs a CUDA GPU (driver and NVVM found by numba-cuda) or numba's CUDA "
            "simulator (set NUMBA_ENABLE_CUDASIM=1 before numba.cuda is imported); neither is available "
            "here: use the CPU backend")


def scramble_multiplier(n: int) -> int:
    """A multiplier coprime to n near n / golden ratio: c -> c * A mod n is a permutation of
    range(n) that spreads neighbouring indices (clustered escape times in an IC grid) evenly
    over the grid's blocks.  c * A < n^2 must fit in int64: n < 3e9."""
    if n <= 2:
        return 1
    a = max(1, int(round(n * GOLDEN)))
    while math.gcd(a, n) != 1:
        a += 1
    return a


def launch_grid(kernel: Any, n: int, block: int, smem: int) -> int:
    """Blocks to launch: no more than the GPU keeps resident (persistent threads take the
    remaining trajectories from the queue), no more than the work needs."""
    need = max(1, math.ceil(n / block))
    if cuda_kernels.SIMULATOR:
        return min(need, SIMULATOR_GRID)
    overload = next(iter(kernel.overloads.values()))
    return max(1, min(need, int(overload.max_cooperative_grid_blocks(block, smem))))


def run_cuda(problem: EnsembleProblem, *, block: int | None = None, grid: int | None = None,
             timing: dict[str, Any] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Integrate an ensemble problem (problem.ensemble_problem) on the GPU.

    Returns (steps_E (N, nE), steps_Q (N, nQ)): int64 step of first crossing of each threshold in
    the problem's sorted order (-1: not within `cycles` periods, 0: the initial condition is
    beyond), bitwise equal to engine.run_cpu's (engine.integrate puts them in the caller's order).

    block, grid: threads per block (default 128, simulator 32) and blocks (default: as many as
    stay resident; the simulator: 2); results do not depend on them.  timing: a dict to receive
    kernel_s (CUDA events around the kernel; the simulator: host clock), wall_s (transfers,
    launch and kernel), grid, block, shared_table, regs_per_thread (GPU only).
    """
    require_cuda()
    pb = problem
    t_wall = time.perf_counter()
    N, nE, nQ = pb.n, pb.thrE2.size, pb.hi.size
    outE = np.full((N, nE), -1, dtype=np.int64)
    outQ = np.full((N, nQ), -1, dtype=np.int64)
    if N:
        # the host forms every product the CPU forms outside an fma (cuda_kernels docstring)
        coef = pb.coefficients().ravel()
        FS = np.ascontiguousarray(pb.F[:, None, None] * pb.sine_table()[None, :, :]).ravel()
        thrE2 = np.zeros(max(nE, 1))
        thrE2[:nE] = pb.thrE2
        thrHi = np.zeros(max(nQ, 1))
        thrHi[:nQ] = pb.hi
        thrLo = np.zeros(max(nQ, 1))
        thrLo[:nQ] = pb.lo
        blk = (checks.check_positive_int("block", block) if block is not None else
               (SIMULATOR_BLOCK if cuda_kernels.SIMULATOR else cuda_kernels.BLOCK))
        shared = FS.nbytes <= cuda_kernels.SHARED_TABLE_BYTES
        smem = FS.nbytes if shared else 0
        warp = SIMULATOR_WARP if cuda_kernels.SIMULATOR else cuda_kernels.WARP
        kernel = cuda_kernels.ensemble_kernel(pb.integrator, shared, blk, math.gcd(blk, warp), pb.code, pb.damping > 0)
        nblk = checks.check_positive_int("grid", grid) if grid is not None else launch_grid(kernel, N, blk, smem)

        d_outE = cuda.to_device(np.full(max(N * nE, 1), -1, dtype=np.int64))
        d_outQ = cuda.to_device(np.full(max(N * nQ, 1), -1, dtype=np.int64))
        args = (cuda.to_device(pb.q0), cuda.to_device(pb.p0), cuda.to_device(pb.pidx), cuda.to_device(coef),
                cuda.to_device(FS), cuda.to_device(thrE2), nE, cuda.to_device(thrLo), cuda.to_device(thrHi), nQ, N,
                pb.steps_per_cycle, pb.cycles, pb.stop_any, scramble_multiplier(N),
                cuda.to_device(np.zeros(1, np.int64)), d_outE, d_outQ, cuda.to_device(pb.code.wpar))
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
    if timing is not None:
        timing["wall_s"] = time.perf_counter() - t_wall
    return outE, outQ
