"""The noisy lanes' machinery compiled once for every well: the well's step and checks
(numerics.noise_loops) reached through function pointers, the machinery (noise_kernels._escape_task)
keyed by the scheme, the noise code, the law and the colour of the noise only."""
from __future__ import annotations

import numpy as np

from safebasins import wells
from safebasins.numerics import escape_probability, noise_kernels, noise_loops, philox, scheme_code, well_loops
from tests.import_graph import closure, graph, module_name


def _escape(well: object, **kw: object) -> np.ndarray:
    q = np.linspace(-0.9, 0.9, 7)
    ds = escape_probability(q, 0.2 * q, 0.05, 0.9, np.pi, noise=0.05, paths=5, xi_max=[0.08, 0.15], t_eval=[20],
                            cycles=20, well=well, seed=3, **kw)
    return np.asarray(ds.first_passage_mean)


def test_a_new_well_reuses_the_noise_machinery():
    """A second well compiles its step and checks, not the machinery; its escapes are its own."""
    first = _escape(wells.from_spec({"expression": "q**2/2 - q**4/4 + q**6/(80*(1 + q**2))"}))
    machinery = set(noise_kernels._escape_task.overloads)
    pointers = set(well_loops._POINTERS)
    second = _escape(wells.from_spec({"expression": "q**2/2 - q**3/3 + q**4/(40*(1 + q**2))"}))
    assert set(noise_kernels._escape_task.overloads) == machinery
    new = set(well_loops._POINTERS) - pointers
    assert sorted(d.py_func.__name__ for d, _ in new) == ["_lane_enter", "_lane_steps"]
    assert np.isfinite(first).all() and not np.array_equal(first, second)


def test_coloured_noise_is_another_step_pointer_of_the_same_well():
    """The colour of the noise is a literal of the machinery and of the step, not of the checks."""
    well = wells.from_spec({"expression": "q**2/2 - q**4/4 + q**6/(90*(1 + q**2))"})
    _escape(well)
    pointers = set(well_loops._POINTERS)
    _escape(well, noise_time=0.3)
    new = set(well_loops._POINTERS) - pointers
    assert [d.py_func.__name__ for d, _ in new] == ["_lane_steps"]


def test_the_rng_key_hashes_every_noise_file_outside_the_engine():
    """RNG_KEY (a literal of every noise kernel) hashes the noise modules the kernels import that
    the scheme key does not (numerics.scheme_code.ENGINE_FILES); wells.elementary by its own hash."""
    engine = {module_name(p) for p in scheme_code.ENGINE_FILES} | {"safebasins.numerics.kernels"}
    noise = {m for m in closure(graph(), "safebasins.numerics.noise_kernels") | {"safebasins.numerics.noise_kernels"}
             if m.startswith("safebasins.numerics.")} - engine
    assert {module_name(p) for p in noise_kernels.RNG_FILES} == noise
    assert {noise_kernels.__file__, noise_loops.__file__, philox.__file__} == set(noise_kernels.RNG_FILES)
    for fn in (noise_loops._lane_steps, noise_loops._lane_enter, noise_kernels._escape_task):
        assert {"rng", "scheme"} <= set(fn.py_func.__code__.co_varnames[:fn.py_func.__code__.co_argcount])
