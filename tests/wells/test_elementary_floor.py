"""The cost floor of benchmarks/floor_elementary.py is a real approximation: its per-step ratios
(bench_wells.py --floor) bound the faithful functions' from below only if its forms compute the
functions to about double precision, on the arguments the benchmarks use."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from safebasins.wells import elementary

ROOT = Path(__file__).resolve().parents[2]


def _floor_module():
    path = ROOT / "benchmarks" / "floor_elementary.py"
    spec = importlib.util.spec_from_file_location("floor_elementary", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("floor_elementary", mod)
    spec.loader.exec_module(mod)
    return mod


FLOOR = _floor_module()
X = np.random.default_rng(5).uniform(-10.0, 10.0, 3000)


@pytest.mark.parametrize(("name", "ref", "kind", "tol"), [
    ("sin", np.sin, "abs", 1e-15), ("cos", np.cos, "abs", 1e-15), ("exp", np.exp, "rel", 1e-15),
    ("expm1", np.expm1, "rel", 2e-15), ("tanh", np.tanh, "rel", 2e-15)])
def test_floor_forms_are_double_precision_approximations(name, ref, kind, tol):
    f = getattr(FLOOR, name)
    got = np.array([f(x) for x in X])
    want = ref(X)
    err = np.abs(got - want) / (1.0 if kind == "abs" else np.abs(want))
    assert err.max() <= tol, (name, err.max())


def test_joint_forms_are_the_single_ones():
    for x in X[:200]:
        assert FLOOR.sincos(x) == (FLOOR.sin(x), FLOOR.cos(x))
        assert FLOOR.exp_expm1(x) == (FLOOR.exp(x), FLOOR.expm1(x))


def test_floor_namespace_replaces_only_the_floor_functions():
    ns = FLOOR.floor_namespace()
    cpu = elementary.cpu()
    for k, v in vars(ns).items():
        assert v is (getattr(FLOOR, k) if k in FLOOR.FLOOR else getattr(cpu, k)), k
