"""The lane machinery compiled once for every well: the well's period loop, replay and state check
(numerics.well_loops) reached through function pointers, the machinery (kernels._run_task) keyed
by the scheme, the shared flag and the kind of tracking only."""
from __future__ import annotations

import numpy as np
from numba import types

from safebasins import wells
from safebasins.numerics import escape_chart, kernels, well_loops


def _chart(well: object) -> np.ndarray:
    q = np.linspace(-1.2, 1.2, 9)
    chart = escape_chart(q, q, 0.05, 0.9, np.pi, xi_max=(0.08, 0.15), cycles=20, well=well)
    return np.asarray(chart.escape_cycle_energy)


def test_a_new_well_reuses_the_machinery():
    """A second well of the same kind of tracking compiles its three functions, not the machinery;
    its chart is its own (not the first well's)."""
    first = _chart(wells.from_spec({"expression": "q**2/2 - q**4/4 + q**6/(70*(1 + q**2))"}))
    machinery = set(kernels._run_task.overloads)
    pointers = set(well_loops._POINTERS)
    second = _chart(wells.from_spec({"expression": "q**2/2 - q**3/3 + q**4/(50*(1 + q**2))"}))
    assert set(kernels._run_task.overloads) == machinery
    new = set(well_loops._POINTERS) - pointers
    assert {d.py_func.__name__ for d, _ in new} == {"_shared_period", "_replay", "_check_state"}
    assert len(new) == 3
    assert np.isfinite(first).any() and not np.array_equal(first, second, equal_nan=True)


def test_a_pointer_signature_is_plain():
    """The pointer's signature takes the keys as plain integers (what the machinery passes); the
    specialisation behind it is on their literals."""
    _chart(None)
    for (_, sig), ptr in well_loops._POINTERS.items():
        plain = ptr.signature()
        assert not any(isinstance(a, types.Literal) for a in plain.args)
        assert any(isinstance(a, types.Literal) for a in sig)
        assert plain.args == tuple(types.unliteral(a) for a in sig)
        assert ptr.__wrapper_address__() > 0
