"""``safebasins continue-attractors``: the dataset of the pipeline's continue_attractors kind (the same
numbers as the library call), the figure, the summary lines; bad options named before anything is
written."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins.analysis.continuation import continue_attractors
from safebasins.cli import main

#: below the escape equation's hysteresis band: one attractor, a run of a few seconds
ARGS = ["continue-attractors", "--well", "cubic", "--F", "0.03,0.035,0.04", "--Omega", "0.85", "--damping", "0.1",
        "--n-grid", "15", "--n-iter", "20", "--step-max", "0.5", "--steps-per-cycle", "16", "--threads", "1",
        "--quiet"]


def test_writes_the_library_dataset(tmp_path: Path) -> None:
    res = CliRunner().invoke(main, [*ARGS, "-o", str(tmp_path / "c")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(tmp_path / "c.nc")
    ref = continue_attractors(0.85, [0.03, 0.035, 0.04], 0.1, "cubic", n_grid=15, n_iter=20, step_max=0.5,
                              steps_per_cycle=16, threads=1)
    assert set(ds.data_vars) == set(ref.data_vars)
    for k in ref.data_vars:
        np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
    assert ds.attrs["parameter"] == "F" and ds.attrs["Omega"] == 0.85 and ds.attrs["damping"] == 0.1
    assert (tmp_path / "c.png").stat().st_size > 0
    lo, hi = ref["attractor_end_parameter"].values[0]
    assert f"attractor 0 (non_resonant): F {lo:.6g} to {hi:.6g}; cliff F = {float(ref['cliff_low'][0]):.6g}" \
           in res.output
    assert f"safe basin: cliff F = {float(ref['safe_cliff_low']):.6g}" in res.output


@pytest.mark.parametrize("extra,option", [(["--damping", "0"], "--damping"),
                                          (["--Omega", "0.8,0.85"], "--Omega"),      # both swept
                                          (["--F", "0.03"], "--F"),                  # neither
                                          (["--F", "0.04,0.03"], "--F"),             # not increasing
                                          (["--F", "0.03,-0.01"], "--F"),
                                          (["--xi-max", "0.2"], "--xi-max"),         # above the cubic's 1/6
                                          (["--n-grid", "5"], "--n-grid"),
                                          (["--step-max", "0"], "--step-max"),
                                          (["--max-points", "2"], "--max-points"),
                                          (["--steps-per-cycle", "2"], "--steps-per-cycle"),
                                          (["--fourier", "exact"], "--fourier")])
def test_bad_options_named(tmp_path: Path, extra: list[str], option: str) -> None:
    args = list(ARGS)
    if extra[0] in args:
        args[args.index(extra[0]) + 1] = extra[1]
    else:
        args += extra
    res = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2 and option in res.output, res.output
    assert not (tmp_path / "bad.nc").exists() and "np.float64" not in res.output


def test_cost_guard_names_allow_expensive(tmp_path: Path) -> None:
    args = list(ARGS)
    args[args.index("--n-grid") + 1] = "1001"
    args[args.index("--n-iter") + 1] = "100000"       # 4.8e12 steps of the labels: above the 1 core-hour
    res = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "big")])
    assert res.exit_code == 2 and "--allow-expensive" in res.output, res.output
    assert not (tmp_path / "big.nc").exists()
