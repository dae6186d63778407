"""End to end on the quick configuration (marker `pipeline`): every dataset with its CF and
provenance attributes and the agreement IoU; per-experiment rerun isolation; archive and
report; -j1 vs -j2, tile count and kill + --rerun-incomplete give identical datasets."""
from __future__ import annotations

import copy
import hashlib
import os
import signal
import subprocess
import tarfile
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from snakemake.utils import update_config

from conftest import ROOT, make_sandbox, run_snakemake, snakemake_cmd
from safebasins import config as sbc
from safebasins import datasets as sd

pytestmark = pytest.mark.pipeline

QUICK_BUDGET_S = 180  # the target for 2 cores (reported, asserted loosely below)


def resolved_quick():
    cfg = sbc.load_yaml(ROOT / "config" / "config.yaml")
    update_config(cfg, sbc.load_yaml(ROOT / "config" / "quick.yaml"))
    return sbc.resolve(sbc.validate_config(cfg))


RES = resolved_quick()
DATASETS = [f for e, p in RES.items() for f in sbc.dataset_files(e, p["kind"], params=p)]
# small subset used for the determinism checks (numeric chart + agreement, bisection, random ICs)
SUBSET = ["results/data/numeric/chart_fig13.nc", "results/data/numeric/fcr_fig10.nc",
          "results/data/numeric/criteria_fig19.nc", "results/data/numeric/chart_fig16.nc"]


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    wd = make_sandbox(tmp_path_factory.mktemp("quick"))
    t0 = time.perf_counter()
    r = run_snakemake(wd, "-j2", "--keep-going", "all")
    elapsed = time.perf_counter() - t0
    print(f"\nquick run (all, -j2): {elapsed:.1f} s")
    (wd / "quick_run_seconds.txt").write_text(f"{elapsed:.1f}\n")
    return wd, r, elapsed


def test_quick_run_completes(quick):
    wd, r, elapsed = quick
    assert r.returncode == 0, (r.stdout[-3000:] + r.stderr[-6000:])
    assert elapsed < 3 * QUICK_BUDGET_S, f"quick run took {elapsed:.0f} s"


def test_every_dataset_with_cf_and_provenance(quick):
    wd, _, _ = quick
    missing = [f for f in DATASETS if not (wd / f).exists()]
    assert not missing, missing
    for f in DATASETS:
        ds = sd.load(wd / f)
        a = ds.attrs
        for k in ("Conventions", "title", "source", "history", "references", "safebasins_version", "git_commit",
                  "config_hash", "parameters", "experiment"):
            assert k in a, (f, k)
        exp = a["experiment"]
        assert a["config_hash"] == sbc.params_hash(RES[exp]), f
        for c in ds.coords:
            if ds[c].dtype.kind in "fi" and c in sd.VARIABLES:
                assert "units" in ds[c].attrs and "long_name" in ds[c].attrs, (f, c)
        if "/numeric/" in f:
            assert "steps_per_cycle" in a, f
    for e in ("fig18", "fig19"):
        f = next(x for x in DATASETS if e in x and "/numeric/" in x)
        assert np.atleast_1d(sd.load(wd / f).attrs["seeds"]).size >= 1


def test_dataset_contents(quick):
    wd, _, _ = quick
    L = lambda f: sd.load(wd / "results" / "data" / f)  # noqa: E731
    fcr = L("analytic/fcr_fig01.nc")
    assert fcr["F_cr"].dims == ("curve", "Omega") and fcr.sizes["curve"] == len(RES["fig01"]["curves"])
    for c in ("xi_max", "xi0", "gamma0", "label"):
        assert c in fcr.coords
    num = L("numeric/fcr_fig10.nc")
    assert num["F_cr"].dims == ("curve", "Omega") and "non_monotone" in num
    assert np.isfinite(num["F_cr"].values).any()
    b5 = L("analytic/basin_fig05.nc")
    for v, dims in (("C", ("gamma_rm", "xi_rm")), ("escapes_rm", ("gamma_rm", "xi_rm")), ("escapes", ("q0", "p0"))):
        assert b5[v].dims == dims, v
    assert b5["escapes"].dtype == bool and "kind" in b5 and "q0_vertex" in b5
    b13 = L("analytic/basin_fig13.nc")
    assert b13["escapes"].dims == ("xi_max", "q0", "p0")
    b16 = L("analytic/basin_fig16.nc")
    assert b16["escapes"].dims == ("F", "q0", "p0")
    st = L("numeric/strobe_fig18.nc")
    assert st["q"].dims == ("sample", "iteration") and not st["escaped"].values.any()
    assert st.sizes["sample"] == RES["fig18"]["n_trajectories"]
    cr = L("numeric/criteria_fig19.nc")
    assert cr["A_E"].dims == ("F", "repeat") and (cr["A_q"] >= cr["A_E"]).all()
    assert "seed" in cr.coords and "rel_diff" in cr
    for e in ("fig20", "fig21"):
        ch = L(f"numeric/chart_{e}.nc")
        assert ch["escape_cycle_energy"].dims == ("xi_max", "q0", "p0")
        assert ch["escape_cycle_displacement"].dims == ("q_max", "q0", "p0")
        n = RES[e]["grid"]["n"]
        assert (ch.sizes["q0"], ch.sizes["p0"]) == tuple(n)


def test_agreement_stored_in_charts(quick):
    wd, _, _ = quick
    for e in ("fig13", "fig14", "fig15", "fig16", "fig17"):
        ch = sd.load(wd / f"results/data/numeric/chart_{e}.nc")
        scan = RES[e]["scan"]
        assert ch["iou"].dims == (scan,) and ch["pixel_agreement"].dims == (scan,), e
        assert ((ch["iou"] >= 0) & (ch["iou"] <= 1)).all() and ((ch["pixel_agreement"] >= 0) & (ch["pixel_agreement"] <= 1)).all()
        for k in ("iou_mean", "iou_min", "pixel_agreement_mean", "agreement_definition"):
            assert k in ch.attrs, (e, k)
        if scan == "F":
            assert ch["escape_cycle_energy"].dims == ("F", "xi_max", "q0", "p0")
        else:
            assert ch["escape_cycle_energy"].dims == ("xi_max", "q0", "p0")


def test_figures_built(quick):
    wd, _, _ = quick
    from safebasins.plotting import catalog

    missing = [p for nn in catalog.FIGURES for p in catalog.figure_paths(nn) if not (wd / p).exists()]
    assert not missing, missing


def test_extras_datasets_and_figures(quick):
    """Beyond-the-paper products (rule `extras`, built by `all`): layout, invariants, reuse."""
    wd, _, _ = quick
    from safebasins.plotting import catalog

    L = lambda f: sd.load(wd / "results" / "data" / "extras" / f)  # noqa: E731
    ero_p = RES["extra_erosion"]
    an, nu = L("erosion_analytic.nc"), L("erosion_numeric.nc")
    assert an["GIM"].dims == ("fourier", "F", "xi_max") and list(an["fourier"].values) == ["paper", "exact"]
    assert nu["GIM"].dims == ("F", "xi_max", "t_eval") and list(nu["t_eval"].values) == ero_p["t_eval"]
    assert list(nu["F"].values) == ero_p["F"] and nu.attrs["cycles"] == ero_p["cycles"]
    for ds in (an, nu):
        for m in ("GIM", "LIM", "IF"):
            np.testing.assert_allclose(ds[m].sel(F=0.0).values, 1.0)
            assert f"F_{m}" in ds
    # one integration per F: the profile can only shrink with the evaluation time
    assert (nu["GIM"].diff("t_eval") <= 1e-12).all() and (nu["IF"].diff("t_eval") <= 1e-12).all()
    assert len(list((wd / "results/data/numeric/parts/extra_erosion").glob("task*_tile*.nc"))) == len(ero_p["F"])
    ta, tn = L("true_basin_analytic.nc"), L("true_basin_numeric.nc")
    assert tn["safe"].dims == ("Psi", "xi_max", "t_eval", "q0", "p0") and tn.sizes["Psi"] == len(RES["extra_true_basin"]["Psi"])
    for ds in (ta, tn):
        assert bool(ds["contained"].all())
        assert (ds["GIM_true"] <= ds["GIM"].min("Psi") + 1e-12).all()
    assert (ta["xi_true"] >= 0).all() and "true_safe_continuous" in ta
    fo = RES["extra_fourier"]
    for e in fo["fcr"]:
        f = L(f"fourier_fcr_{e}.nc")
        assert f["rel_error"].dims == ("curve", "fourier", "Omega") and "rms_rel_error" in f
        assert f.attrs["source_config_hash"] == sd.load(wd / f"results/data/numeric/fcr_{e}.nc").attrs["config_hash"]
    for e in fo["iou"]:
        f = L(f"fourier_iou_{e}.nc")
        assert f["iou"].dims[0] == "fourier" and ((f["iou"] >= 0) & (f["iou"] <= 1)).all()
        assert f.attrs["source_config_hash"] == sd.load(wd / f"results/data/numeric/chart_{e}.nc").attrs["config_hash"]
    import matplotlib.image as mpimg
    import json

    for name in catalog.EXTRA_FIGURES:
        png, pdf = (wd / x for x in catalog.extra_figure_paths(name))
        assert png.stat().st_size > 20_000 and pdf.stat().st_size > 5_000, name
        assert float(np.var(mpimg.imread(png)[..., :3])) > 1e-3, f"blank figure {name}"
        nb = json.loads((wd / catalog.extra_executed_notebook_path(name)).read_text())
        assert not [o for c in nb["cells"] for o in c.get("outputs", []) if o.get("output_type") == "error"]


def test_nothing_to_do_and_param_change_reruns_only_own_chain(quick, tmp_path):
    wd, r, _ = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    # (`datasets`, not `all`: figure rules also depend on plotting code edited in parallel)
    again = run_snakemake(wd, "-n", "datasets")
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr, again.stdout[-2000:]
    over = tmp_path / "f16.yaml"
    over.write_text("figures:\n  fig16:\n    F: [0.005, 0.012]\n")
    dry = run_snakemake(wd, "-n", "datasets", configfiles=("config/quick.yaml", over))
    assert dry.returncode == 0, dry.stderr[-2000:]
    exps = set(__import__("re").findall(r"experiment=(fig\d\d)", dry.stdout + dry.stderr))
    assert exps == {"fig16"}, exps


def test_archive_and_report(quick):
    wd, r, _ = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    a = run_snakemake(wd, "-j1", "archive")
    assert a.returncode == 0, a.stderr[-3000:]
    arch = wd / "results/archive/safebasins-results.tar.gz"
    with tarfile.open(arch) as tar:
        names = tar.getnames()
        members = {n.split("/", 1)[1]: tar.extractfile(n).read() for n in names}
    for f in DATASETS:
        assert f.removeprefix("results/") in members, f
    for k in ("config.resolved.yaml", "environment.lock", "MANIFEST.sha256", "environment.installed.txt"):
        assert k in members, k
    for line in members["MANIFEST.sha256"].decode().splitlines():
        digest, name = line.split("  ", 1)
        assert hashlib.sha256(members[name]).hexdigest() == digest, name
    rep = run_snakemake(wd, "--report", "results/report.html")
    assert rep.returncode == 0, rep.stderr[-3000:]
    assert (wd / "results/report.html").stat().st_size > 10_000


def _compare(ref_wd, wd, files):
    for f in files:
        sd.assert_same_content(sd.load(ref_wd / f), sd.load(wd / f))


def test_j1_and_tiles_identical(quick, tmp_path):
    ref, r, _ = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    wd = make_sandbox(tmp_path / "j1")
    tiles = tmp_path / "tiles.yaml"
    tiles.write_text("numerics:\n  tiles: 3\n")
    r1 = run_snakemake(wd, "-j1", *SUBSET, configfiles=("config/quick.yaml", tiles))
    assert r1.returncode == 0, r1.stderr[-3000:]
    assert len(list((wd / "results/data/numeric/parts/fig13").glob("task0_tile*of3.nc"))) == 3
    _compare(ref, wd, SUBSET)


def test_killed_run_rerun_incomplete_identical(quick, tmp_path):
    ref, r, _ = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    wd = make_sandbox(tmp_path / "kill")
    env = dict(os.environ, PATH=f"{Path(os.sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    proc = subprocess.Popen(snakemake_cmd(wd, "-j2", *SUBSET), cwd=wd, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    logs = wd / "results/logs/chart_tile"
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None and not (logs.exists() and any(logs.rglob("*.log"))):
        time.sleep(0.05)
    killed_mid_run = proc.poll() is None
    if killed_mid_run:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=60)
    assert killed_mid_run, "the run finished before it could be killed"
    assert not all((wd / f).exists() for f in SUBSET)
    run_snakemake(wd, "--unlock")
    r2 = run_snakemake(wd, "-j2", "--rerun-incomplete", *SUBSET)
    assert r2.returncode == 0, r2.stderr[-3000:]
    leftovers = list((wd / "results").rglob(".*.tmp"))
    assert not leftovers, leftovers
    _compare(ref, wd, SUBSET)
