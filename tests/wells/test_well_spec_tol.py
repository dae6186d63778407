"""The tol key of a well spec, alike in the API, the config and the command line."""
import copy
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

from safebasins import wells
from safebasins.pipeline.config import REPO_ROOT, ConfigError, load_yaml, validate_config

SCRIPT = Path(sys.executable).with_name("safebasins")
#: E_b = 1.2e-4, V computed as 0.21 + ... - 0.21: 5e-13 relative at that scale, short of 1e-13
TEXT = "q**2/2 + 0.3*q - 0.147/(0.7-q) + 0.21"


def _validate(well):
    cfg = copy.deepcopy(load_yaml(REPO_ROOT / "config" / "config.yaml"))
    cfg["experiments"] = {"mine": {"kind": "basin_rm", "well": well, "F": 0.002, "Omega": 0.2, "xi_max": 8e-5,
                                   "grid": {"q0": [-0.03, 0.05], "p0": [-0.01, 0.01], "n": 5}}}
    return validate_config(cfg)


def test_api():
    assert wells.from_spec({"expression": TEXT, "tol": 1e-11}).tol == 1e-11
    assert wells.from_spec({"polynomial": [0, 0, 0.5, 0, -0.25], "tol": 1e-12}).spec()["tol"] == 1e-12


def test_config():
    cfg = _validate({"expression": TEXT, "tol": 1e-11})
    assert cfg["experiments"]["mine"]["well"] == {"expression": TEXT, "tol": 1e-11}
    with pytest.raises(ConfigError, match="experiments.mine.well"):
        _validate({"expression": TEXT})                         # the construction's message, naming the key
    with pytest.raises(ConfigError, match="experiments.mine.well"):
        _validate({"expression": TEXT, "tol": 1.0})             # outside [1e-15, 1e-2]


def test_command_line(tmp_path):
    base = [str(SCRIPT), "basin", "--F", "0.002", "--Omega", "0.2", "--xi-max", "8e-5", "--n", "5", "--n-gamma", "8",
            "--n-xi", "6", "--n-points", "20", "--no-plot", "-q"]
    ok = subprocess.run(base + ["--well", f"{{expression: '{TEXT}', tol: 1e-11}}", "-o", "run"], cwd=tmp_path,
                        capture_output=True, text=True, timeout=300)
    assert ok.returncode == 0, ok.stderr
    with xr.open_dataset(tmp_path / "run.nc") as ds:
        assert ds.attrs["well_tol"] == 1e-11 and ds.attrs["well_expression"] == TEXT
    bad = subprocess.run(base + ["--well", f"{{expression: '{TEXT}'}}", "-o", "bad"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "'--well'" in bad.stderr and "tol: 1e-11" in bad.stderr, bad.stderr
