"""The basin_measures kind (config ``damped.escape_equation_measures`` and
``damped.quartic_measures``): resolved with its damping and measures, refused where a measure
cannot run (naming the key), and built end to end on the quick config."""
from __future__ import annotations

import pytest
import xarray as xr

from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.plan import plan
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

NAMES = ("damped_escape_measures", "damped_quartic_measures")


def test_resolved(base):
    run = plan(base)
    for name in NAMES:
        exp = run.experiments[name]
        p = exp.params
        assert exp.kind.name == "basin_measures" and p["damping"] > 0 and p["grid"]["n"] == [401, 401]
        assert p["measures"] == {"box": 5, "radius": 8.0, "n_balls": 1000, "eps": [2, 4, 8, 16]}
        assert [x.path for x in exp.products] == [f"results/data/extras/{name}.nc"]
        assert exp.kind.cost(p) == len(p["F"]) * 401 * 401 * p["n_iter"] * p["steps_per_cycle"]
    assert run.experiments[NAMES[0]].params["well"] == {"name": "cubic"}


@pytest.mark.parametrize("override,key", [
    ({"damping": 0.0}, "escape_equation_measures.damping"),
    ({"measures": {"radius": 200}}, "escape_equation_measures.measures.radius"),
    ({"measures": {"box": 402}}, "escape_equation_measures.measures.box"),
    ({"measures": {"eps": [2, 300]}}, "escape_equation_measures.measures.eps"),
    ({"F": [0.05, 0.05]}, r"escape_equation_measures.F\[1\]"),
])
def test_refused_naming_the_key(base, override, key):
    with pytest.raises(ConfigError, match=key):
        plan(merged(base, {"damped": {"escape_equation_measures": override}}))


@pytest.mark.pipeline
def test_quick_run_builds_the_figures(quick):
    wd, res = quick      # the shared quick run of `all` (tests/pipeline/conftest.py) builds them
    assert res.returncode == 0, res.stderr[-3000:]
    for name in NAMES:
        ds = xr.open_dataset(wd / f"results/data/extras/{name}.nc")
        assert ds["S_bb"].dims == ("F", "labelling") and ds.attrs["damping"] > 0 and "provenance" not in ds
        assert (wd / f"results/figures/{name}.png").stat().st_size > 0
        assert "alpha" in (wd / f"results/captions/{name}.rst").read_text()
