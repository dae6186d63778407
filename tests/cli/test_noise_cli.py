"""``safebasins escape-probability``: the dataset is the library's escape_probability value for value
(white and coloured noise, the well's own IC window), with the averaged theory's map and agreement
as theory.escape_probability and probability_agreement give them (or the reason there is none),
zero noise gives escape_chart's escapes, bad options are named before anything runs, and the
command is listed."""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins import theory
from safebasins.analysis.agreement import probability_agreement
from safebasins.cli import main
from safebasins.core.averaged_theory import MIN_CELLS
from safebasins.numerics import escape_chart, escape_probability
from safebasins.wells import resolve_well

BASE = ["escape-probability", "--F", "0.05", "--Omega", "0.9", "--xi-max", "0.2", "--noise", "0.06", "--t-eval", "2,4",
        "--n", "5x4", "--paths", "12", "--quiet"]
VARIABLES = ("P_escape", "P_escape_low", "P_escape_high", "survival", "first_passage_mean", "first_passage_sem",
             "censored_fraction")


def invoke(args, tmp_path, prefix="ep"):
    return CliRunner().invoke(main, [*args, "-o", str(tmp_path / prefix)], catch_exceptions=False)


def window(well, nq, np_):
    (q_lo, q_hi), (p_lo, p_hi) = resolve_well(well).ic_window()
    return np.linspace(q_lo, q_hi, nq), np.linspace(p_lo, p_hi, np_)


@pytest.mark.parametrize("extra, well, kw", [
    (["--damping", "0.05", "--seed", "7"], "quartic", dict(damping=0.05, seed=7)),
    (["--well", "cubic", "--F", "0.06", "--Omega", "0.85", "--xi-max", "0.16", "--noise-time", "0.5",
      "--steps-per-cycle", "24", "--cycles", "5", "--no-plot"], "cubic",
     dict(F=0.06, Omega=0.85, xi_max=0.16, noise_time=0.5, steps_per_cycle=24, cycles=5)),
    (["--variates", "five-point", "--no-theory", "--no-plot"], "quartic", dict(variates="five-point")),
], ids=["quartic-white-damped", "cubic-coloured", "quartic-five-point"])
def test_writes_the_library_dataset(tmp_path, extra, well, kw):
    res = invoke([*BASE, *extra], tmp_path)
    assert res.exit_code == 0, res.output
    with xr.open_dataset(tmp_path / "ep.nc") as ds:
        q0, p0 = window(well, 5, 4)
        args = {"F": 0.05, "Omega": 0.9, "xi_max": 0.2, **kw}
        ref = escape_probability(q0, p0, args.pop("F"), args.pop("Omega"), 0.0, noise=0.06, paths=12, t_eval=[2, 4],
                                 well=well, grid=True, **args)
        np.testing.assert_array_equal(ds["q0"].values, q0)
        np.testing.assert_array_equal(ds["p0"].values, p0)
        for v in VARIABLES:
            np.testing.assert_array_equal(ds[v].values, ref[v].values, err_msg=v)
        params = json.loads(ds.attrs["parameters"])
        assert params["command"] == "escape-probability" and params["paths"] == 12
        assert params["variates"] == ds.attrs["variates"] == kw.get("variates", "gaussian")
        assert params["cycles"] == ref.attrs["cycles"] and ds.attrs["seed"] == kw.get("seed", 0)
        # the command line is this process's sys.argv (in-process runner: pytest's or an xdist
        # worker's), so only its program name is known here; test_cli checks it from a subprocess
        assert ds.attrs["history"].split()[0] == "safebasins"
        assert "safebasins escape-probability ep" in ds.attrs["title"]
    png = tmp_path / "ep.png"
    assert png.exists() != ("--no-plot" in extra)
    mean = float(ref["P_escape"].sel(t_eval=4).mean())
    assert f"within 4 cycles: mean P_escape {mean:.4f} over 20 ICs" in res.output


@pytest.mark.parametrize("damping", [0.0, 0.05])
def test_zero_noise_is_the_escape_chart(tmp_path, damping):
    res = invoke([*BASE, "--noise", "0", "--n", "6x5", "--paths", "3", "--damping", str(damping), "--no-plot"],
                 tmp_path)
    assert res.exit_code == 0, res.output
    q0, p0 = window("quartic", 6, 5)
    chart = escape_chart(q0, p0, 0.05, 0.9, 0.0, xi_max=0.2, cycles=4, damping=damping)
    tc = chart["escape_cycle_energy"].sel(xi_max=0.2).values
    with xr.open_dataset(tmp_path / "ep.nc") as ds:
        P = ds["P_escape"].values
        assert set(np.unique(P)) <= {0.0, 1.0}
        for k, t in enumerate((2, 4)):
            np.testing.assert_array_equal(P[:, :, k], (tc <= t).astype(float), err_msg=f"t_eval = {t}")
        assert 0 < P[:, :, 1].sum() < P[:, :, 1].size        # some escape, some stay: the test can fail


@pytest.mark.parametrize("args, option, reason", [
    (["--noise", "-0.1"], "'--noise'", ">= 0"),
    (["--paths", "0"], "'--paths'", "paths"),
    (["--seed", "-1"], "'--seed'", "0<=x"),
    (["--cycles", "3"], "'--t-eval'", "beyond the horizon"),
    (["--t-eval", "1,3,5"], "'--t-eval'", "at most 4"),             # added to BASE's 2,4
    (["--noise-time", "0.01"], "'--noise-time'", "shorter than the step"),      # the library's check, named
    (["--variates", "uniform"], "'--variates'", "five-point"),
    (["--xi-max", "0.3"], "'--xi-max'", "1/4"),
    (["--Omega", "0.02"], "'--steps-per-cycle'", "steps_per_cycle >="),
], ids=lambda v: v if isinstance(v, str) else " ".join(v))
def test_bad_options_named_before_anything_runs(tmp_path, args, option, reason):
    res = CliRunner().invoke(main, [*BASE, *args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2, res.output
    last = res.output.strip().splitlines()[-1]
    assert option in last and reason in last, last
    assert list(tmp_path.iterdir()) == []


def test_cost_guard_counts_paths(tmp_path):
    res = CliRunner().invoke(main, [*BASE, "--n", "2000", "--paths", "100000", "-o", str(tmp_path / "x")])
    assert res.exit_code == 2 and "--allow-expensive" in res.output, res.output
    assert list(tmp_path.iterdir()) == []


def test_help_lists_the_command():
    res = CliRunner().invoke(main, ["--help"])
    assert res.exit_code == 0 and "escape-probability" in res.output
    res = CliRunner().invoke(main, ["escape-probability", "--help"])
    assert res.exit_code == 0 and all(o in res.output for o in ("--noise", "--noise-time", "--paths", "--t-eval"))



@pytest.mark.parametrize("args", [
    BASE,
    ["basin-measures", "--F", "0.055,0.07", "--Omega", "0.85", "--xi-max", "0.2", "--damping", "0.1"],
    ["hilltop-saddle", "--F", "0.055", "--Omega", "0.85", "--xi-max", "0.2", "--damping", "0.1"],
], ids=["escape-probability", "basin-measures", "hilltop-saddle"])
def test_numeric_commands_refuse_fourier(args, tmp_path):
    """--fourier changes nothing these commands compute: refused by name, not ignored."""
    res = CliRunner().invoke(main, [*args, "--fourier", "exact", "-o", str(tmp_path / "x")])
    assert res.exit_code == 2 and "--fourier" in res.output, res.output
    assert not list(tmp_path.iterdir())


THEORY = ["--theory-cells", "16x20", "--theory-steps-per-cycle", "6"]


def test_theory_map_and_agreement_are_the_library_calls(tmp_path):
    res = invoke([*BASE, *THEORY, "--damping", "0.05"], tmp_path)
    assert res.exit_code == 0, res.output
    q0, p0 = window("quartic", 5, 4)
    ens = escape_probability(q0, p0, 0.05, 0.9, 0.0, noise=0.06, paths=12, xi_max=0.2, t_eval=[2, 4], damping=0.05,
                             grid=True)
    th = theory.escape_probability(q0, p0, 0.05, 0.9, 0.0, 0.2, noise=0.06, t_eval=[2, 4], damping=0.05,
                                   cells=(16, 20), steps_per_cycle=6)
    ref = probability_agreement(th, ens)
    with xr.open_dataset(tmp_path / "ep.nc") as ds:
        np.testing.assert_array_equal(ds["P_escape_theory"].values, th["P_escape"].values)
        for k in ("P_escape_mean_abs_difference", "P_escape_max_abs_difference"):
            assert ds[k].dims == ("t_eval",)
            np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
            assert ds.attrs[k] == ref.attrs[k]
        for k in ("P_escape_mean_abs_difference_uncertain", "P_escape_theory_within_wilson"):
            assert ds[k].dims == () and float(ds[k]) == ref.attrs[k], k
        assert ds.attrs["theory_solver"] == th.attrs["solver"] and list(ds.attrs["theory_cells"]) == [16, 20]
        assert ds.attrs["theory_steps_per_cycle"] == 6 and "theory_reason" not in ds.attrs
        assert 0 < ds.attrs["P_escape_mean_abs_difference"] < 0.2          # compared, and not a constant
    assert (tmp_path / "ep.png").exists()
    assert f"mean |P_escape_theory - P_escape| {ref.attrs['P_escape_mean_abs_difference']:.4f}" in res.output


@pytest.mark.parametrize("extra, reason", [
    (["--no-theory"], "theory: false"),
    (["--xi-max", "0.25"], "below the barrier energy"),        # the theory refuses the threshold
], ids=["no-theory", "barrier"])
def test_no_theory_says_why(tmp_path, extra, reason):
    res = invoke([*BASE, *THEORY, "--no-plot", *extra], tmp_path)
    assert res.exit_code == 0, res.output
    with xr.open_dataset(tmp_path / "ep.nc") as ds:
        assert ds.attrs["theory"] == "none" and reason in ds.attrs["theory_reason"]
        assert not [v for v in ds.data_vars if "theory" in str(v) or "abs_difference" in str(v)]
    assert "no averaged theory: " in res.output


@pytest.mark.parametrize("args, reason", [
    (["--theory-cells", "4x20"], f">= {MIN_CELLS} (n_gamma, n_J)"),
    (["--theory-cells", "16,20"], "N or NQxNP"),
    (["--theory-steps-per-cycle", "0"], "steps_per_cycle"),
])
def test_bad_theory_options_named(tmp_path, args, reason):
    res = CliRunner().invoke(main, [*BASE, *args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2, res.output
    last = res.output.strip().splitlines()[-1]
    assert f"'{args[0]}'" in last and reason in last, last
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- the cost guard counts the theory
# a tiny ensemble (20 ICs x 12 paths) with a far too large theory: 2048^2 cells x 200 cycles of 8 steps
HUGE_THEORY = ["--theory-cells", "2048", "--t-eval", "200"]


def test_cost_guard_refuses_a_huge_theory_naming_its_options(tmp_path):
    from safebasins.pipeline.config import REPO_ROOT, load_yaml
    from safebasins.pipeline.cost import analytic_cost
    from safebasins.pipeline.plan import plan
    from tests.pipeline.test_config import merged

    res = CliRunner().invoke(main, [*BASE, *HUGE_THEORY, "-o", str(tmp_path / "huge")])
    assert res.exit_code == 2, res.output
    last = res.output.strip().splitlines()[-1]
    assert "slow-flow evaluations" in last and "--theory-cells" in last and "--allow-expensive" in last, last
    assert list(tmp_path.iterdir()) == []                          # refused before anything ran
    # the pipeline's count of the same theory (one noise level, 5 x 4 ICs, t_eval 2, 4, 200)
    base = load_yaml(REPO_ROOT / "config" / "config.yaml")
    over = {"noise": [0.06], "grid": {"n": [5, 4]}, "t_eval": [2, 4, 200], "cycles": 200, "theory_cells": [2048, 2048]}
    exp = plan(merged(base, {"noise": {"quartic_escape_probability": over}})).experiments[
        "noise_quartic_escape_probability"]
    assert f"needs {analytic_cost(exp):.2e} slow-flow evaluations" in last, last


def test_cost_guard_passes_without_the_theory_and_at_the_defaults(tmp_path):
    # the same horizon without the theory (the ensemble alone is small)
    res = invoke([*BASE, *HUGE_THEORY, "--no-theory", "--no-plot"], tmp_path, "none")
    assert res.exit_code == 0, res.output
    # the default grid (200 x 200 ICs) and the theory's default cells and steps
    res = invoke([*BASE, "--n", "200", "--paths", "2", "--no-plot"], tmp_path, "default")
    assert res.exit_code == 0, res.output
    assert "averaged theory vs ensemble" in res.output
