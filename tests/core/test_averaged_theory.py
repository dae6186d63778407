"""The averaged theory's solver settings: the one home of its defaults, its smallest grid and its
horizon, which the theory, the pipeline's schemas and the command line read."""
from __future__ import annotations

import inspect

import numpy as np
import pytest

from safebasins import theory
from safebasins.core.averaged_theory import CELLS, MIN_CELLS, STEPS_PER_CYCLE, check_cells, theory_cycles


def test_defaults_are_the_theory_signature() -> None:
    sig = inspect.signature(theory.escape_probability).parameters
    assert sig["cells"].default == CELLS and sig["steps_per_cycle"].default == STEPS_PER_CYCLE
    assert inspect.signature(theory.mean_first_passage).parameters["cells"].default == CELLS
    assert min(CELLS) >= MIN_CELLS


def test_check_cells_accepts_the_smallest_grid() -> None:
    assert check_cells((MIN_CELLS, MIN_CELLS)) == (MIN_CELLS, MIN_CELLS)
    out = check_cells((np.int64(16), 20))
    assert out == (16, 20) and all(type(n) is int for n in out)


@pytest.mark.parametrize("cells", [(MIN_CELLS - 1, 20), (20, MIN_CELLS - 1), (16,), (16, 20, 4), [16, 20], (16.0, 20),
                                   (True, 20), "16x20"], ids=repr)
def test_check_cells_refuses_naming_cells(cells) -> None:
    with pytest.raises(ValueError, match=rf"^cells must be a pair of integers >= {MIN_CELLS}"):
        check_cells(cells)


def test_the_theory_refuses_below_the_smallest_grid() -> None:
    with pytest.raises(ValueError, match="^cells must"):
        theory.escape_probability([0.1], [0.0], 0.05, 0.9, 0.0, 0.2, noise=0.05, t_eval=[1],
                                  cells=(MIN_CELLS - 1, 20))


@pytest.mark.parametrize("t_eval, cycles", [([0.0], 1), ([0.5], 1), ([1.0], 1), ([1.0, 2.5], 3), (np.array([4.0]), 4),
                                            (7, 7)])
def test_theory_cycles_is_the_largest_t_eval_rounded_up(t_eval, cycles) -> None:
    assert theory_cycles(t_eval) == cycles
