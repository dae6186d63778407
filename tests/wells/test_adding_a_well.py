"""docs/adding-a-well.md followed once: a named well is one entry of wells.NAMED_WELLS, and every
consumer (API, config schema and validation, command line, dataset attributes, compiled form on
the CPU and its GPU source) reads it from there."""
from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from safebasins import wells
from safebasins.analysis.agreement import iou
from safebasins.numerics import escape_chart
from safebasins.theory import slow_flow_escapes

NAME = "soft_quartic"


@pytest.fixture
def soft_quartic(monkeypatch):
    """The one entry of the doc, added for the duration of a test."""
    monkeypatch.setitem(wells.NAMED_WELLS, NAME, (lambda: wells.expression("q**2/2 - q**4/8", name=NAME),
                                                  "a softening quartic V = q^2/2 - q^4/8 (E_b = 1/2)"))
    wells._build.cache_clear()
    yield NAME
    wells._build.cache_clear()


def test_named_well_everywhere(soft_quartic, tmp_path):
    w = wells.resolve_well(NAME)
    assert w.name == NAME and w.barriers == pytest.approx((-np.sqrt(2.0), np.sqrt(2.0)), rel=1e-14)
    assert w.barrier_energy == pytest.approx(0.5, rel=1e-14)
    assert wells.from_attrs(wells.well_attrs(w)) is w            # datasets name it; built once
    # the config schema lists it; a config naming it validates (pipeline.config.well_schema)
    from safebasins.pipeline.config import build_schema
    assert NAME in build_schema()["$defs"]["well"]["oneOf"][0]["enum"]
    # API: numerics against the slow flow at small forcing (Omega near the linear frequency 1)
    q0 = np.linspace(-1.0, 1.0, 41)
    p0 = np.linspace(-0.7, 0.7, 41)
    ch = escape_chart(q0, p0, 0.004, 0.9, np.pi, xi_max=(0.3,), cycles=200, well=NAME)
    assert ch.attrs["well"] == NAME and "q**4" in ch.attrs["well_potential"]
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    theory_safe = ~slow_flow_escapes(Q, P, 0.004, 0.9, np.pi, 0.3, well=NAME)
    numeric_safe = ch["escape_cycle_energy"].isel(xi_max=0).values > 200
    assert iou(theory_safe, numeric_safe) > 0.93
    # the compiled form: one source, the generated V and dV (what the GPU compiles too)
    code = w.compiled
    assert "mul(" in w.source and code.key == wells.resolve_well(NAME).compiled.key
    # the command line (in process, so that it sees the added entry)
    from safebasins.cli import main
    res = CliRunner().invoke(main, ["basin", "--well", NAME, "--F", "0.004", "--Omega", "0.9", "--xi-max", "0.3",
                                    "--n", "21", "--no-plot", "-q", "-o", str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    import xarray as xr
    ds = xr.load_dataset(tmp_path / "b.nc")
    assert ds.attrs["well"] == NAME and NAME in ds.attrs["title"]


def test_unknown_name_is_named():
    with pytest.raises(ValueError, match="unknown well 'soft_quartic'"):
        wells.resolve_well(NAME)
