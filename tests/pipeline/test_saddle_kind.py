"""The hilltop_saddle kind (config ``damped.escape_equation_saddle``): resolved with its damping,
manifold and tangency options, refused where it cannot run (naming the key), and built end to end
on the quick config."""
from __future__ import annotations

import pytest
import xarray as xr

from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.plan import plan
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

NAME = "damped_escape_saddle"


def test_resolved(base):
    exp = plan(base).experiments[NAME]
    p = exp.params
    assert exp.kind.name == "hilltop_saddle" and p["damping"] == 0.1 and p["well"] == {"name": "cubic"}
    assert p["grid"]["n"] == [201, 201] and p["F"] == [0.055, 0.07]
    assert p["manifolds"] == {"iterations": None, "ds_max": 0.02, "rtol": 1e-10}
    assert p["tangency"] == {"enabled": True, "xtol": 1e-6, "ds_max": 0.02, "rtol": 1e-9}
    assert [x.path for x in exp.products] == [f"results/data/extras/{NAME}.nc"]


@pytest.mark.parametrize("override,key", [
    ({"damping": 0.0}, "escape_equation_saddle.damping"),
    ({"F": [0.05, 0.05]}, r"escape_equation_saddle.F\[1\]"),
    ({"manifolds": {"ds_max": 0.0}}, "escape_equation_saddle.manifolds.ds_max"),
    ({"tangency": {"enabled": "yes"}}, "escape_equation_saddle.tangency.enabled"),
])
def test_refused_naming_the_key(base, override, key):
    with pytest.raises(ConfigError, match=key):
        plan(merged(base, {"damped": {"escape_equation_saddle": override}}))


@pytest.mark.pipeline
def test_quick_run_builds_the_figure(quick):
    wd, res = quick      # the shared quick run of `all` (tests/pipeline/conftest.py) builds it
    assert res.returncode == 0, res.stderr[-3000:]
    ds = xr.open_dataset(wd / f"results/data/extras/{NAME}.nc")
    assert ds["escape_cycle"].dims == ("F", "q0", "p0") and ds.attrs["damping"] > 0
    assert (wd / f"results/figures/{NAME}.png").stat().st_size > 0
    assert "Melnikov threshold" in (wd / f"results/captions/{NAME}.rst").read_text()
