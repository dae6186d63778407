"""A view of the explorer (a well and a point of its sliders): checks, and the URL query that the
live page and its static picture read."""
from __future__ import annotations

import json
from urllib.parse import parse_qs

import numpy as np
import pytest

from safebasins.explore import ranges, state


def test_missing_values_are_the_well_defaults():
    r = ranges.well_ranges("pendulum")
    f = state.forcing_of(r, {"F": 0.2, "Psi": None})
    assert (f.F, f.Omega, f.Psi, f.xi_max, f.damping) == (0.2, r.Omega.value, r.Psi.value, r.xi_max.value, 0.0)


@pytest.mark.parametrize("values, match", [({"F": -0.1}, "F must be >= 0"), ({"Omega": 0.0}, "Omega must be > 0"),
                                           ({"Psi": np.inf}, "Psi must be finite"),
                                           ({"xi_max": 0.25}, "xi_max must be < 1/4"),
                                           ({"xi_max": 0.0}, "xi_max must lie in"),
                                           ({"damping": -1e-3}, "damping must be >= 0"),
                                           ({"beta": 0.1}, "beta: not a parameter")])
def test_bad_values_name_the_parameter(values, match):
    with pytest.raises(ValueError, match=match):
        state.forcing_of(ranges.well_ranges("quartic"), values)


@pytest.mark.parametrize("well", ["sech2", {"expression": "q**2/2 - q**3/3"}, {"polynomial": [0, 0, 0.5, -0.1]}])
def test_query_round_trip_is_exact(well):
    r = ranges.well_ranges(well)
    f = state.forcing_of(r, {"F": 0.1 / 3, "Omega": 2 ** -0.5, "Psi": -np.pi / 7, "damping": 1e-3})
    query = state.to_query(r, f)
    args = {k: [x.encode() for x in v] for k, v in parse_qs(query).items()}     # as tornado hands them over
    r2, f2 = state.view("quartic", {"F": 0.5}, args)
    assert r2.spec == r.spec and f2 == f


def test_query_overrides_the_command_line_point():
    r, f = state.view("pendulum", {"F": 0.1, "Omega": 0.8}, {"Omega": ["0.7"]})
    assert r.name == "pendulum" and (f.F, f.Omega) == (0.1, 0.7)
    r, f = state.view("pendulum", {"F": 0.1}, {"well": "cubic"})          # another well: its defaults
    assert r.name == "cubic" and f.F == r.F.value


@pytest.mark.parametrize("args, match", [({"F": ["abc"]}, "F must be a number"),
                                         ({"frequency": ["1"]}, "frequency: not a key"),
                                         ({"well": ["{expression: 1"]}, "well: cannot read"),
                                         ({"well": [json.dumps({"expression": "x"})]}, "unknown name")])
def test_bad_queries_name_the_key(args, match):
    with pytest.raises(ValueError, match=match):
        state.view("quartic", None, args)
