"""The `safebasins` console script, driven through its installed entry point on tiny cases: files
with the pipeline's layout and provenance, figures, tiles equal to one library call, `info`,
--help everywhere, and bad arguments rejected with exit status 2 naming the option."""
from __future__ import annotations

import json
import os
import pty
import select
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

SCRIPT = Path(sys.executable).with_name("safebasins")
CHART = ["chart", "--F", "0.01", "--Omega", "0.9", "--Psi", "pi", "--xi-max", "0.14,0.18", "--q-max", "0.8",
         "--grid", "-0.9,0.9,-0.7,0.7", "--n", "12x10", "--cycles", "20", "--tiles", "3"]
FCR = ["fcr", "--xi-max", "0.15", "--Omega-range", "0.8,1.0,21", "--numeric", "--numeric-Omega", "0.85,0.95,9",
       "--cycles", "20", "--n-scan", "4", "--tol", "1e-3"]
BASIN = ["basin", "--F", "0.0876", "--Omega", "0.92", "--xi-max", "0.24", "--n", "12x10", "--n-gamma", "24",
         "--n-xi", "20", "--n-points", "64"]


def run(args, cwd, **kw):
    assert SCRIPT.exists(), f"no console script {SCRIPT}: reinstall the package (pip install -e .)"
    return subprocess.run([str(SCRIPT), *args], cwd=cwd, capture_output=True, text=True, timeout=120, **kw)


def run_on_terminal(args, cwd):
    """Run with stderr on a pseudo-terminal (the progress bar shows only on a terminal)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([str(SCRIPT), *args], cwd=cwd, stdout=subprocess.PIPE, stderr=slave, text=True)
    os.close(slave)
    err = b""
    while True:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # EIO: the terminal closed
                break
            if not chunk:
                break
            err += chunk
        elif proc.poll() is not None:
            break
    out = proc.communicate(timeout=120)[0]
    os.close(master)
    return proc.returncode, out, err.decode(errors="replace")


def check_provenance(ds, command, contract):
    """CF globals, provenance and the layout of the pipeline product (its contract)."""
    from safebasins import __version__
    from safebasins.io.datasets import params_hash

    a = ds.attrs
    assert a["Conventions"] == "CF-1.10" and a["safebasins_version"] == __version__
    assert a["history"].startswith(f"safebasins {command} ") and a["git_commit"] and a["date_created"]
    params = json.loads(a["parameters"])
    assert params["command"] == command and a["config_hash"] == params_hash(params)
    assert f"safebasins {command}" in a["title"]
    for name, dims in contract.items():
        assert name in ds.variables and ds[name].dims == tuple(dims), (name, dims)
    return params


def check_png(path):
    import matplotlib.image as mpimg

    img = mpimg.imread(path)
    assert img.ndim == 3 and min(img.shape[:2]) > 200
    assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 20  # drawn, not blank


@pytest.fixture(scope="module")
def chart_run(tmp_path_factory):
    wd = tmp_path_factory.mktemp("chart")
    rc, out, err = run_on_terminal([*CHART, "-o", "sub/c"], wd)
    assert rc == 0, err
    return wd, out, err


def test_chart_writes_the_pipeline_layout_with_provenance_and_a_figure(chart_run):
    from safebasins.analysis.agreement import iou
    from safebasins.pipeline.kinds.basins import chart_contract
    from safebasins.theory import slow_flow_escapes

    wd, out, err = chart_run
    assert "escape chart: 100%" in err and "3/3 [" in err and "tile/s" in err, err  # bar per tile, with ETA
    assert "wrote sub/c.nc" in out and "wrote sub/c.png" in out
    with xr.open_dataset(wd / "sub/c.nc") as ds:
        ds.load()
    params = check_provenance(ds, "chart", {**chart_contract(), "iou": ("xi_max",), "pixel_agreement": ("xi_max",)})
    assert params["kind"] == "basin_chart" and params["xi_max"] == [0.14, 0.18] and params["q_max"] == [0.8]
    assert ds.attrs["Psi"] == np.pi and ds.attrs["scan"] == "xi_max" and ds.attrs["agreement_t_eval"] == 20
    # the stored IoU is that of the slow-flow prediction and the numeric basin (escape cycle > 20)
    Q, P = np.meshgrid(ds["q0"].values, ds["p0"].values, indexing="ij")
    for i, xi in enumerate(ds["xi_max"].values):
        analytic = ~np.asarray(slow_flow_escapes(Q, P, 0.01, 0.9, np.pi, xi), bool)
        numeric = ds["escape_cycle_energy"].values[i] > 20
        assert ds["iou"].values[i] == pytest.approx(float(iou(analytic, numeric)), abs=1e-12)
        assert f"xi_max = {xi:g}: IoU = {ds['iou'].values[i]:.4f}" in out
    check_png(wd / "sub/c.png")


def test_chart_tiles_equal_one_escape_chart_call(chart_run):
    """Three row tiles gathered = one library call on the whole grid (trajectories are independent)."""
    from safebasins.numerics import escape_chart

    wd, _, _ = chart_run
    with xr.open_dataset(wd / "sub/c.nc") as ds:
        ds.load()
    q0, p0 = np.linspace(-0.9, 0.9, 12), np.linspace(-0.7, 0.7, 10)
    ref = escape_chart(q0, p0, 0.01, 0.9, np.pi, xi_max=(0.14, 0.18), q_max=(0.8,), cycles=20, grid=True)
    assert np.array_equal(ds["q0"].values, q0) and np.array_equal(ds["p0"].values, p0)
    for v in ("escape_cycle_energy", "escape_cycle_displacement"):
        assert np.array_equal(ds[v].values, ref[v].values), v


def test_info_reports_contents_provenance_and_agreement(chart_run):
    wd, _, _ = chart_run
    res = run(["info", "sub/c.nc"], wd)
    assert res.returncode == 0, res.stderr
    with xr.open_dataset(wd / "sub/c.nc") as ds:
        attrs = dict(ds.attrs)
        iou = ds["iou"].values
    out = res.stdout
    for text in ("dimensions: xi_max=2, q0=12, p0=10, q_max=1", "q0 (q0): [-0.9, 0.9]",
                 "escape_cycle_energy (xi_max, q0, p0) float64",
                 "safebasins_version: " + attrs["safebasins_version"], "git_commit: " + attrs["git_commit"],
                 "config_hash: " + attrs["config_hash"], "date_created: " + attrs["date_created"],
                 "history: safebasins chart", '    command: "chart"', "headline numbers (agreement at t_eval = 20 EC):",
                 f"iou: xi_max = 0.14: {iou[0]:.4f}, xi_max = 0.18: {iou[1]:.4f}"):
        assert text in out, text


def test_fcr_analytic_and_numeric_in_omega_chunks_equal_one_call(tmp_path):
    from safebasins.numerics import critical_forcing_numeric
    from safebasins.pipeline.kinds.fcr import ANALYTIC_CONTRACT, NUMERIC_CONTRACT
    from safebasins.theory import critical_forcing

    res = run([*FCR, "-o", "f"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert [line.split()[1] for line in res.stdout.splitlines()[:3]] == ["f.nc", "f_numeric.nc", "f.png"]
    ana, num = (xr.load_dataset(tmp_path / f) for f in ("f.nc", "f_numeric.nc"))
    check_provenance(ana, "fcr", ANALYTIC_CONTRACT)
    params = check_provenance(num, "fcr", NUMERIC_CONTRACT)
    assert params["kind"] == "fcr_compare" and len(params["numeric"]["Omega"]) == 9
    np.testing.assert_allclose(ana["Omega"].values, np.linspace(0.8, 1.0, 21), rtol=0, atol=1e-12)
    np.testing.assert_allclose(num["Omega"].values, np.linspace(0.85, 0.95, 9), rtol=0, atol=1e-12)
    ref = critical_forcing(ana["Omega"].values, 0.15)
    np.testing.assert_array_equal(ana["F_cr"].isel(curve=0).values, ref["F_cr"].values)
    # 9 Omega points run in chunks of 4 (the progress bar's steps): the same as one library call
    one = critical_forcing_numeric(num["Omega"].values, 0.15, cycles=20, n_scan=4, tol=1e-3)
    for v in ("F_cr", "F_cr_low", "F_cr_high", "F_escape_low", "F_escape_all", "non_monotone"):
        np.testing.assert_array_equal(num[v].isel(curve=0).values, one[v].values, err_msg=v)
    assert num.attrs["bisection_levels"] == one.attrs["bisection_levels"]
    check_png(tmp_path / "f.png")


def test_basin_writes_the_manifold_layout(tmp_path):
    from safebasins.pipeline.kinds.basins import basin_contract

    res = run([*BASIN, "-o", "b", "--no-plot"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.nc"]
    ds = xr.load_dataset(tmp_path / "b.nc")
    params = check_provenance(ds, "basin", basin_contract(manifold=True))
    assert params["manifold"] == {"n_gamma": 24, "n_xi": 20, "xi_top": 0.2499}  # schema default of xi_top
    assert ds.sizes["gamma_rm"] == 24 and ds.sizes["q0"] == 12 and ds.sizes["p0"] == 10
    safe = int((~ds["escapes"].astype(bool)).sum())
    assert f"analytic safe: {safe} of 120 ICs" in res.stdout


HELP = {"": ["chart", "fcr", "basin", "info"],
        "chart": ["--xi-max", "--grid", "--tiles", "--t-eval", "--out PREFIX", "[default: 3000]", "--well"],
        "fcr": ["--Omega-range", "--numeric / --no-numeric", "--n-scan", "[default: 301]"],
        "basin": ["--xi-top", "0.2499", "--well"], "info": ["FILE"]}


def run_all(cases, tmp_path_factory):
    """Independent invocations, two at a time (the machine is shared), each in its own folder with a
    non-netCDF file in it: {index: (result, folder)}."""
    from concurrent.futures import ThreadPoolExecutor

    folders = [tmp_path_factory.mktemp("case") for _ in cases]
    for wd in folders:
        (wd / "not_netcdf.txt").write_text("plain text\n")
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda c: run(*c), zip(cases, folders)))
    return dict(enumerate(zip(results, folders)))


@pytest.fixture(scope="module")
def help_runs(tmp_path_factory):
    return run_all([[c, "--help"] if c else ["--help"] for c in HELP], tmp_path_factory)


@pytest.mark.parametrize("i, command", list(enumerate(HELP)))
def test_help(i, command, help_runs):
    res, _ = help_runs[i]
    assert res.returncode == 0 and res.stdout.startswith("Usage: safebasins"), res.stderr
    for text in HELP[command]:
        assert text in res.stdout, text


BAD = [
    (["chart", "--F", "nan", "--Omega", "0.9", "--xi-max", "0.15"], "'--F'", "NaN"),
    (["chart", "--F", "0.01", "--Omega", "inf", "--xi-max", "0.15"], "'--Omega'", "finite"),
    (["chart", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.15", "--n", "1"], "'--n'", "at least 3"),
    (["chart", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.15", "--grid", "1,-1,0,1"], "'--grid'", "empty q0"),
    (["chart", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.25"], "'--xi-max'", "1/4"),
    (["chart", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.15", "--cycles", "10", "--t-eval", "20"],
     "'--t-eval'", "horizon"),
    (["fcr", "--xi-max", "0.15", "--xi-ini", "0.2"], "'--xi-ini'", "below the truncation level"),
    (["fcr", "--xi-max", "0.15", "--Omega-range", "1,0.5,10"], "'--Omega-range'", "empty range"),
    (["basin", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.2", "--n", "5", "--n-points", "2"],
     "'--n-points'", "n_points must be >= 3"),                    # raised by the library, mapped to the option
    (["chart", "--F", "0.01", "--Omega", "0.9", "--Psi", "pi/0", "--xi-max", "0.15"], "'--Psi'", "divides by zero"),
    (["chart", "--F", "0.01", "--Omega", "0.02", "--xi-max", "0.15"], "'--steps-per-cycle'",
     "use steps_per_cycle >= 281"),                                # checked before anything is integrated
    (["fcr", "--xi-max", "0.15", "--numeric", "--numeric-Omega", "0.01,0.02,2"], "'--steps-per-cycle'",
     "steps_per_cycle >="),
    (["info", "not_netcdf.txt"], "'FILE'", "not a readable netCDF file"),
]


@pytest.fixture(scope="module")
def bad_runs(tmp_path_factory):
    return run_all([args + (["-o", "x"] if args[0] != "info" else []) for args, _, _ in BAD], tmp_path_factory)


@pytest.mark.parametrize("i, option, reason", [(i, o, r) for i, (_, o, r) in enumerate(BAD)],
                         ids=[" ".join(b[0][:1] + b[0][-2:]) for b in BAD])
def test_bad_arguments_are_usage_errors_naming_the_option(i, option, reason, bad_runs):
    res, wd = bad_runs[i]
    assert res.returncode == 2, res.stderr
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("Error: Invalid value for") and option in last and reason in last, last
    assert "Traceback" not in res.stderr and res.stdout == ""
    assert sorted(p.name for p in wd.iterdir()) == ["not_netcdf.txt"]  # nothing written


def test_choices_are_the_librarys():
    from safebasins.cli.options import BACKENDS
    from safebasins.numerics import engine

    from safebasins.cli.options import FOURIER
    from safebasins.wells.quartic import FOURIER_VARIANTS

    assert tuple(BACKENDS) == tuple(engine.BACKENDS) and tuple(FOURIER) == tuple(FOURIER_VARIANTS)


@pytest.mark.parametrize("args, text", [
    (["chart", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.15", "--n", "30000x30000", "--cycles", "5000"],
     "core-hours"),
    (["basin", "--F", "0.01", "--Omega", "0.9", "--xi-max", "0.15", "--n-gamma", "50000", "--n-xi", "50000"],
     "slow-flow evaluations"),
])
def test_cost_guard_refuses_before_computing_unless_allowed(tmp_path, args, text):
    """The pipeline's default budgets guard the CLI too: refused with exit 2 naming
    --allow-expensive, before anything is computed or written."""
    res = run([*args, "-o", "x"], tmp_path)
    assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
    last = res.stderr.strip().splitlines()[-1]
    assert text in last and "--allow-expensive" in last, last
    assert list(tmp_path.iterdir()) == []


def test_cost_of_a_command_is_the_pipelines():
    from safebasins.cli.options import cost_guard
    from safebasins.pipeline.cost import budgets

    b = budgets()
    assert b["budget_core_hours"] > 0 and b["budget_analytic_evaluations"] > 0
    assert cost_guard("basin_rm", {}, allow_expensive=True) is None    # allowed: nothing is estimated


def test_unwritable_output_is_refused_before_computing(tmp_path):
    target = tmp_path / "file"
    target.write_text("")
    res = run([*CHART[:9], "-o", str(target / "run")], tmp_path)      # a file where a folder should be
    assert res.returncode == 2 and "'--out'" in res.stderr and "is a file, not a folder" in res.stderr, res.stderr
    (tmp_path / "run.nc").mkdir()
    res = run([*CHART[:9], "-o", "run"], tmp_path)
    assert res.returncode == 2 and "run.nc is a folder" in res.stderr, res.stderr


def test_fcr_damping_one_curve_per_beta_recorded(tmp_path):
    res = run(["fcr", "--xi-max", "0.15", "--Omega-range", "0.9,0.95,2", "--damping", "0.01,0.02", "--numeric",
               "--numeric-Omega", "0.9,0.95,2", "--cycles", "100", "--n-scan", "0", "--tol", "1e-3", "--no-plot",
               "-o", "d"], tmp_path)
    assert res.returncode == 0, res.stderr
    with xr.open_dataset(tmp_path / "d.nc") as a, xr.open_dataset(tmp_path / "d_numeric.nc") as n:
        assert a["damping"].values.tolist() == n["damping"].values.tolist() == [0.01, 0.02]
        assert "F_cr_undamped" in a and (a["F_cr"] >= a["F_cr_undamped"] - 1e-3).all()
        assert json.loads(a.attrs["parameters"])["damping"] == [0.01, 0.02]
    bad = run(["fcr", "--xi-max", "0.15", "--damping", "0,0.02", "-o", "x"], tmp_path)
    assert bad.returncode == 2 and "'--damping'" in bad.stderr and "every value must be > 0" in bad.stderr
