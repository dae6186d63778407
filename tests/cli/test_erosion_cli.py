"""``safebasins stochastic-erosion``: the dataset is the library's stochastic_erosion profile value
for value, with stochastic_erosion_theory's GIM/LIM/IF where the averaged theory applies (or the
reason there is none), bad options are named before anything runs, and the figure is written."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins.analysis import stochastic_erosion
from safebasins.analysis.stochastic_integrity import stochastic_erosion_theory
from safebasins.cli import main
from safebasins.core.averaged_theory import MIN_CELLS
from tests.cli.test_quiet_cli import STRICT, run

BASE = ["stochastic-erosion", "--F", "0,0.01", "--Omega", "0.9", "--Psi", "pi", "--xi-max", "0.18",
        "--noise", "0.01,0.02", "--epsilon", "0.3,0.5", "--t-eval", "1,3", "--n", "5x4",
        "--grid=-0.95,0.95,-0.75,0.75", "--paths", "12", "--steps-per-cycle", "16", "--theory-cells", "16x20",
        "--theory-steps-per-cycle", "6", "--quiet"]
Q0, P0 = np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4)
MEASURES = ("GIM", "LIM", "IF")


def invoke(args, tmp_path, prefix="er"):
    return CliRunner().invoke(main, [*args, "-o", str(tmp_path / prefix)], catch_exceptions=False)


def test_writes_the_library_profile_with_the_theory(tmp_path):
    res = invoke(BASE, tmp_path)
    assert res.exit_code == 0, res.output
    ref = stochastic_erosion(Q0, P0, [0.0, 0.01], 0.9, math.pi, noise=[0.01, 0.02], epsilon=[0.3, 0.5], paths=12,
                             xi_max=0.18, t_eval=[1, 3], steps_per_cycle=16)
    th = stochastic_erosion_theory(Q0, P0, [0.0, 0.01], 0.9, math.pi, noise=[0.01, 0.02], epsilon=[0.3, 0.5],
                                   xi_max=0.18, t_eval=[1, 3], cells=(16, 20), steps_per_cycle=6)
    with xr.open_dataset(tmp_path / "er.nc") as ds:
        assert ds["GIM"].dims == ("F", "noise", "epsilon", "t_eval")
        for k in (*MEASURES, *(m + "_conservative" for m in MEASURES)):
            np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
        for m in MEASURES:
            np.testing.assert_array_equal(ds[m + "_theory"].values, th[m].transpose(*ds[m].dims).values, err_msg=m)
        assert 0 < float(ds["GIM_theory"].min()) < 1 and 0 < float(ds["GIM"].min()) < 1     # eroded, not empty
        assert ds.attrs["theory_solver"] == th.attrs["solver"] and list(ds.attrs["theory_cells"]) == [16, 20]
        params = json.loads(ds.attrs["parameters"])
        assert params["command"] == "stochastic-erosion" and params["paths"] == 12 and params["noise"] == [0.01, 0.02]
        assert "safebasins stochastic-erosion er" in ds.attrs["title"]
    assert (tmp_path / "er.png").exists()
    assert "|GIM_theory - GIM| mean" in res.output


def test_single_values_and_no_theory(tmp_path):
    """One F, noise, epsilon: no dimension (the library's scalars); --no-theory: the reason stored;
    five-point variates passed through to the ensembles."""
    args = [a if a not in ("0,0.01", "0.01,0.02", "0.3,0.5") else a.split(",")[-1] for a in BASE]
    res = invoke([*args, "--no-theory", "--no-conservative", "--no-plot", "--seed", "5", "--variates", "five-point"],
                 tmp_path)
    assert res.exit_code == 0, res.output
    ref = stochastic_erosion(Q0, P0, 0.01, 0.9, math.pi, noise=0.02, epsilon=0.5, paths=12, xi_max=0.18,
                             t_eval=[1, 3], steps_per_cycle=16, seed=5, conservative=False, variates="five-point")
    with xr.open_dataset(tmp_path / "er.nc") as ds:
        assert ds["GIM"].dims == ("t_eval",)
        assert ds.attrs["variates"] == "five-point"
        for k in MEASURES:
            np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
        assert ds.attrs["theory"] == "none" and "theory: false" in ds.attrs["theory_reason"]
        assert not [v for v in ds.data_vars if str(v).endswith(("_theory", "_conservative"))]
    assert not (tmp_path / "er.png").exists()


def test_zero_noise_level_has_the_noise_free_theory(tmp_path):
    res = invoke([*_without(BASE, "--noise"), "--noise", "0,0.02", "--no-plot"], tmp_path)
    assert res.exit_code == 0, res.output
    with xr.open_dataset(tmp_path / "er.nc") as ds:
        assert "theory_reason" not in ds.attrs
        assert ds["GIM"].sel(noise=0.0).notnull().all() and ds["GIM_theory"].sel(noise=0.0).notnull().all()


@pytest.mark.parametrize("args, option, reason", [
    (["--epsilon", "1.5"], "'--epsilon'", "(0, 1)"),
    (["--epsilon", "0"], "'--epsilon'", "(0, 1)"),
    (["--epsilon", ""], "'--epsilon'", "at least one value"),
    (["--noise", ""], "'--noise'", "at least one value"),
    (["--noise", "-0.1"], "'--noise'", ">= 0"),
    (["--F", "-0.01"], "'--F'", ">= 0"),
    (["--F", "0.02,0.01"], "'--F'", "strictly increasing"),
    (["--noise", "0.02,0.01"], "'--noise'", "strictly increasing"),
    (["--epsilon", "0.5,0.3"], "'--epsilon'", "strictly increasing"),
    (["--noise", "0.01,0.01"], "'--noise'", "given twice"),
    (["--epsilon", "0.1"], "'--paths'", "--no-conservative"),        # 12 paths certify no epsilon < 0.24
    (["--t-eval", "3,1"], "'--t-eval'", "strictly increasing"),
    (["--cycles", "2"], "'--t-eval'", "beyond the horizon"),
    (["--theory-cells", "4"], "'--theory-cells'", f">= {MIN_CELLS}"),
    (["--paths", "0"], "'--paths'", "paths"),
    (["--xi-max", "0.3"], "'--xi-max'", "1/4"),
], ids=lambda v: v if isinstance(v, str) else " ".join(v))
def test_bad_options_named_before_anything_runs(tmp_path, args, option, reason):
    # the option given last wins over BASE's
    res = CliRunner().invoke(main, [*_without(BASE, args[0]), *args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2, res.output
    last = res.output.strip().splitlines()[-1]
    assert option in last and reason in last, last
    assert list(tmp_path.iterdir()) == []


def _without(args, option):
    """BASE without ``option`` and its value (list options are joined, not replaced, when repeated)."""
    if option not in args:
        return list(args)
    i = args.index(option)
    return [*args[:i], *args[i + 2:]]


def test_cost_guard_counts_paths(tmp_path):
    res = CliRunner().invoke(main, [*_without(BASE, "--paths"), "--n", "1000", "--paths", "100000",
                                    "-o", str(tmp_path / "x")])
    assert res.exit_code == 2 and "--allow-expensive" in res.output, res.output
    assert list(tmp_path.iterdir()) == []


def test_cost_guard_counts_the_theory_per_forcing_and_noise_level(tmp_path):
    # 1024^2 cells x 100 cycles of 6 steps: one solve fits the analytic budget, 2 F x 2 sigma do not
    from safebasins.analysis.noise_theory import theory_evaluations
    from safebasins.pipeline.cost import budgets

    kw = dict(noise=[0.01, 0.02], t_eval=[1, 3, 100], n_ics=20, well="quartic", cells=(1024, 1024), steps_per_cycle=6)
    budget = budgets()["budget_analytic_evaluations"]
    assert theory_evaluations(solves=1, **kw) < budget < theory_evaluations(solves=4, **kw)
    res = CliRunner().invoke(main, [*_without(BASE, "--theory-cells"), "--theory-cells", "1024", "--t-eval", "100",
                                    "-o", str(tmp_path / "x")])
    assert res.exit_code == 2, res.output
    last = res.output.strip().splitlines()[-1]
    assert f"needs {theory_evaluations(solves=4, **kw):.2e} slow-flow evaluations" in last, last
    assert "--theory-cells" in last and "--allow-expensive" in last, last
    assert list(tmp_path.iterdir()) == []


def test_help_lists_the_command():
    res = CliRunner().invoke(main, ["--help"])
    assert res.exit_code == 0 and "stochastic-erosion" in res.output
    res = CliRunner().invoke(main, ["stochastic-erosion", "--help"])
    assert res.exit_code == 0 and all(o in res.output for o in ("--noise", "--epsilon", "--paths", "--theory",
                                                                "--no-conservative", "--theory-cells"))


def test_warns_nothing(tmp_path):
    """Run as a user runs it (a child process, runtime and user warnings as errors): no warning."""
    res = run([*BASE, "-o", "x"], tmp_path, env=STRICT)
    assert res.returncode == 0, res.stderr
    assert "Warning" not in res.stderr and "Warning" not in res.stdout, res.stderr
    assert (tmp_path / "x.png").stat().st_size > 0
