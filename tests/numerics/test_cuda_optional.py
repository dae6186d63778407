"""The CUDA engine is an extra (safebasins[cuda]: numba-cuda): without it "auto" runs on the CPU,
and asking for "cuda" (API or --backend) says which extra to install, never a traceback of
numba's internals (numba alone has numba.cuda but not the numba.cuda.core the engine needs)."""
from __future__ import annotations

import importlib.util
import re

import numpy as np
import pytest
from click.testing import CliRunner

from safebasins.numerics import engine, escape_chart

INSTALL = "pip install 'safebasins[cuda]'"


@pytest.fixture
def without_numba_cuda(monkeypatch):
    real = importlib.util.find_spec

    def find_spec(name, *args, **kwargs):
        return None if name == "numba_cuda" or name.startswith("numba_cuda.") else real(name, *args, **kwargs)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)


def test_auto_runs_on_the_cpu_without_numba_cuda(without_numba_cuda):
    assert engine.resolve_backend("auto") == "cpu"
    q = np.linspace(-0.5, 0.5, 3)
    ref = escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=3)
    auto = escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=3, backend="auto")
    assert np.array_equal(ref["escape_cycle_energy"].values, auto["escape_cycle_energy"].values)


def test_cuda_without_numba_cuda_names_the_extra(without_numba_cuda):
    with pytest.raises(ImportError, match=rf"numba-cuda .* not installed: {re.escape(INSTALL)}$"):
        engine.cuda_engine()
    with pytest.raises(ImportError, match="safebasins\\[cuda\\]"):
        escape_chart([0.1], [0.0], F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=3, backend="cuda")


def test_cli_backend_cuda_without_numba_cuda_is_a_usage_error_naming_the_extra(without_numba_cuda, tmp_path):
    from safebasins.cli import main

    res = CliRunner().invoke(main, ["chart", "--F", "0.01", "--Omega", "0.9", "--Psi", "pi", "--xi-max", "0.14",
                                    "--n", "4", "--cycles", "5", "--backend", "cuda", "-o", str(tmp_path / "c")])
    assert res.exit_code == 2, res.output
    assert "--backend" in res.output and INSTALL in res.output and "Traceback" not in res.output
    assert not list(tmp_path.iterdir())


@pytest.mark.skipif(importlib.util.find_spec("numba_cuda") is None,
                    reason="numba-cuda (safebasins[cuda]) not installed")
def test_with_numba_cuda_the_engine_module_is_the_cuda_engine():
    from safebasins.numerics import cuda_engine

    assert engine.cuda_engine() is cuda_engine
