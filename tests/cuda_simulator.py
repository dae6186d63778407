"""numba's CUDA simulator in a subprocess: the tests that compare the GPU code with the CPU's run
their GPU side as a script with NUMBA_ENABLE_CUDASIM=1 (the simulator must be switched on before
numba.cuda is first imported), its cases as JSON on stdin.

The simulator runs every CUDA thread as a Python thread, and the threads of a block meet at its
barriers.  Free to run on several cores, they pass the GIL between cores at every meeting: the
noisy ensemble's simulator run took 130-210 s alone on a 2-core AMD EPYC, 9 s on one core (and
about 46 s inside make test, where the other core is busy anyway).  So the script pins itself to
one CPU (:func:`pin_to_one_cpu`, first thing in its ``__main__``)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

__all__ = ["run_simulator", "pin_to_one_cpu"]

ROOT = Path(__file__).resolve().parents[1]


def run_simulator(script: str | Path, payload: str, timeout: float) -> subprocess.CompletedProcess[str]:
    """``python script`` with the simulator switched on, the package's source and the repository
    on its path, ``payload`` on stdin; its output captured."""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1",
               PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, str(script)], env=env, input=payload, capture_output=True, text=True,
                          timeout=timeout)


def pin_to_one_cpu() -> None:
    """Runs this thread, and the threads it starts from now on (the simulator's), on one of the
    CPUs it may use (picked by process id, so that two suites' children spread)."""
    cpus = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpus[os.getpid() % len(cpus)]})
