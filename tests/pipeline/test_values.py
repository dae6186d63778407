"""safebasins.pipeline.values.fmt: the one number/angle formatter of the command line and of the
pipeline's figure texts (angles as multiples of pi, never 3.142)."""
from __future__ import annotations

import math

import pytest

from safebasins.pipeline.config import load_kinds
from safebasins.pipeline.registry import KINDS
from safebasins.pipeline.values import fmt


@pytest.mark.parametrize("v,text", [(math.pi, "pi"), (-math.pi, "-pi"), (math.pi / 2, "pi/2"), (-math.pi / 2, "-pi/2"),
                                    (3 * math.pi / 4, "3pi/4"), (2 * math.pi, "2pi"), (0.0, "0"), (0.3, "0.3")])
def test_angles_as_multiples_of_pi(v, text):
    assert fmt(v, angle=True) == text


def test_numbers_and_strings():
    assert fmt(math.pi) == "3.14159" and fmt(0.0876) == "0.0876" and fmt("pi") == "pi"


def test_cli_uses_the_same_formatter():
    from safebasins.cli import output

    assert output.fmt is fmt


@pytest.mark.parametrize("Psi,text", [(math.pi, "Psi = pi,"), (math.pi / 2, "Psi = pi/2,"), (0.3, "Psi = 0.3,")])
def test_integrity_map_caption_writes_Psi_with_pi(Psi, text):
    params = {"xi_max": 0.2, "Psi": Psi, "Omega": [0.9, 1.0], "F": [0.01, 0.02], "grid": {"n": [11, 11]},
              "cycles": 100}
    load_kinds()
    caption, _ = KINDS["integrity_map"].default_figure_text("integrity_map", params)
    assert text in caption and "3.142" not in caption
