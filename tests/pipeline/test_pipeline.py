"""End to end on the quick configuration (marker `pipeline`): every dataset follows its
contract (registry) with CF and provenance attributes, the stored agreement is recomputed
independently; per-experiment rerun isolation; archive (Workflow Run RO-Crate) and report;
-j1 vs -j2, tile count and kill + --rerun-incomplete give identical datasets."""
from __future__ import annotations

import hashlib
import json
import re
import os
import signal
import subprocess
import tarfile
import time

import numpy as np
import pytest
import xarray as xr

from safebasins.core.cf import VARIABLES
from safebasins.io.compare import assert_same_content
from safebasins.io.datasets import load, params_hash
from safebasins.pipeline.plan import plan
from tests.pipeline.sandbox import ROOT, make_sandbox, run_snakemake, snakemake_cmd, snakemake_env

pytestmark = pytest.mark.pipeline

RUN = plan([ROOT / "config" / "config.yaml", ROOT / "config" / "quick.yaml"])
RES = RUN.params()
DATASETS = RUN.datasets()
# small subset used for the determinism checks (numeric chart + agreement, bisection, random ICs)
SUBSET = ["results/data/numeric/chart_fig13.nc", "results/data/numeric/fcr_fig10.nc",
          "results/data/numeric/criteria_fig19.nc", "results/data/numeric/chart_fig16.nc"]


# the quick run (fixture `quick`) is shared with the other pipeline modules: tests/pipeline/conftest.py


def test_quick_run_completes(quick):
    wd, r = quick
    assert r.returncode == 0, (r.stdout[-3000:] + r.stderr[-6000:])


def test_every_dataset_follows_its_contract(quick):
    """Each dataset has the variables and dims its product declares, CF globals, provenance,
    and units/long_name on every numeric variable named in the CF table."""
    wd, _ = quick
    missing = [f for f in DATASETS if not (wd / f).exists()]
    assert not missing, missing
    for f in DATASETS:
        ds = load(wd / f)
        for v, dims in RUN.product(f).contract.items():
            assert v in ds.variables and ds[v].dims == tuple(dims), (f, v, ds[v].dims if v in ds.variables else None)
        a = ds.attrs
        for k in ("Conventions", "title", "source", "history", "references", "safebasins_version", "git_commit",
                  "config_hash", "parameters", "experiment"):
            assert k in a, (f, k)
        exp = RUN.experiment_of(f)
        assert a["experiment"] == exp.name and a["config_hash"] == params_hash(RES[exp.name]), f
        assert a["title"] == RUN.product(f).title, f
        for v in ds.variables:
            if ds[v].dtype.kind in "fi" and v in VARIABLES:
                assert "units" in ds[v].attrs and "long_name" in ds[v].attrs, (f, v)
        if "/numeric/" in f:
            assert "steps_per_cycle" in a, f
    for e in ("fig18", "fig19"):
        ds = load(wd / next(x for x in DATASETS if e in x and "/numeric/" in x))
        assert np.atleast_1d(ds.attrs["seeds"]).size >= 1


def test_stored_agreement_recomputed_independently(quick):
    """The IoU stored in each Figs 13-17 chart equals |A and N| / |A or N| recomputed here from
    the analytic basin file and the escape times, and the slow flow is accurate at small F
    (IoU >= 0.85 at the quick resolution) while the basin erodes at the largest F of Fig 17."""
    wd, _ = quick
    for e in ("fig13", "fig14", "fig15", "fig16", "fig17"):
        ch = xr.load_dataset(wd / f"results/data/numeric/chart_{e}.nc")
        an = xr.load_dataset(wd / f"results/data/analytic/basin_{e}.nc")
        scan = RES[e]["scan"]
        esc = ch["escape_cycle_energy"].values
        safe_num = esc[:, 0] if scan == "F" else esc          # (scan, q0, p0)
        safe_num = safe_num > RES[e]["cycles"]
        safe_an = ~an["escapes"].values.astype(bool)
        inter = (safe_num & safe_an).sum(axis=(1, 2))
        union = (safe_num | safe_an).sum(axis=(1, 2))
        np.testing.assert_allclose(ch["iou"].values, inter / union, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(ch["safe_numeric"].values, safe_num.sum(axis=(1, 2)))
        if e != "fig17":
            assert (ch["iou"].values >= 0.85).all(), (e, ch["iou"].values)
    f17 = xr.load_dataset(wd / "results/data/numeric/chart_fig17.nc")["iou"].values
    assert f17[-1] < f17[0] - 0.2, f17


def test_figures_built_without_errors(quick):
    """Every figure of the plan: PNG and PDF written, not blank, its notebook ran without error."""
    import matplotlib.image as mpimg

    wd, _ = quick
    for fig in RUN.figures():
        png, pdf = wd / fig.png, wd / fig.pdf
        assert png.exists() and pdf.exists(), fig.name
        assert float(np.var(mpimg.imread(png)[..., :3])) > 1e-3, f"blank figure {fig.name}"
        nb = json.loads((wd / fig.executed_notebook).read_text())
        assert not [o for c in nb["cells"] for o in c.get("outputs", []) if o.get("output_type") == "error"], fig.name


def test_extras_datasets_and_figures(quick):
    """Beyond-the-paper products (rule `extras`, built by `all`): layout, invariants, reuse."""
    wd, _ = quick
    L = lambda f: load(wd / "results" / "data" / "extras" / f)
    ero_p = RES["extra_erosion"]
    an, nu = L("extra_erosion_analytic.nc"), L("extra_erosion_numeric.nc")
    assert an["GIM"].dims == ("fourier", "F", "xi_max") and list(an["fourier"].values) == ["paper", "exact"]
    assert nu["GIM"].dims == ("F", "xi_max", "t_eval") and list(nu["t_eval"].values) == ero_p["t_eval"]
    assert list(nu["F"].values) == ero_p["F"] and nu.attrs["cycles"] == ero_p["cycles"]
    for ds in (an, nu):
        for m in ("GIM", "LIM", "IF"):
            np.testing.assert_allclose(ds[m].sel(F=0.0).values, 1.0)
            assert f"F_{m}" in ds
    # one integration per F: the profile can only shrink with the evaluation time
    assert (nu["GIM"].diff("t_eval") <= 1e-12).all() and (nu["IF"].diff("t_eval") <= 1e-12).all()
    # numerics.tiles = 0: the numeric dataset integrated its F tasks itself (no tile jobs, no tile files)
    assert not (wd / "results/data/numeric/parts").exists()
    ta, tn = L("extra_true_basin_analytic.nc"), L("extra_true_basin_numeric.nc")
    assert tn["safe"].dims == ("Psi", "xi_max", "t_eval", "q0", "p0")
    assert tn.sizes["Psi"] == len(RES["extra_true_basin"]["Psi"])
    for ds in (ta, tn):
        assert bool(ds["contained"].all())
        assert (ds["GIM_true"] <= ds["GIM"].min("Psi") + 1e-12).all()
    assert (ta["xi_true"] >= 0).all() and "true_safe_continuous" in ta
    fo = RES["extra_fourier"]
    for e in fo["fcr"]:
        f = L(f"extra_fourier_fcr_{e}.nc")
        assert f["rel_error"].dims == ("curve", "fourier", "Omega") and "rms_rel_error" in f
        assert f.attrs["source_config_hash"] == load(wd / f"results/data/numeric/fcr_{e}.nc").attrs["config_hash"]
    for e in fo["iou"]:
        f = L(f"extra_fourier_iou_{e}.nc")
        assert f["iou"].dims[0] == "fourier" and ((f["iou"] >= 0) & (f["iou"] <= 1)).all()
        assert f.attrs["source_config_hash"] == load(wd / f"results/data/numeric/chart_{e}.nc").attrs["config_hash"]


def test_nothing_to_do_and_param_change_reruns_only_own_chain(quick, tmp_path):
    wd, r = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    # (`datasets`, not `all`: figure rules also depend on plotting code edited in parallel)
    again = run_snakemake(wd, "-n", "datasets")
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr, again.stdout[-2000:]
    over = tmp_path / "f16.yaml"
    over.write_text("figures:\n  fig16:\n    F: [0.005, 0.012]\n")
    dry = run_snakemake(wd, "-n", "datasets", configfiles=("config/quick.yaml", over))
    assert dry.returncode == 0, dry.stderr[-2000:]
    # job blocks of the dry run, without the target rule (its input lists every dataset)
    blocks = re.split(r"^(?:local)?rule ", dry.stdout + dry.stderr, flags=re.M)[1:]
    out = "".join(b for b in blocks if not b.startswith("datasets:"))
    outputs = {f for line in re.findall(r"^\s+output: (.+)$", out, re.M) for f in line.split(", ")}
    # fig16's chain: its parameters, tiles and datasets, and the datasets that read them
    # (extra_fourier's IoU comparison of fig16), nothing else
    own = set(RUN.experiments["fig16"].dataset_files())
    downstream = {p for p in DATASETS if p not in own and any(
        f in own for v in RUN.product_inputs(p).values() for f in ([v] if isinstance(v, str) else v))}
    chain = own | downstream | {"results/params/fig16.yaml"} | set(RUN.tile_files("fig16"))
    assert outputs and outputs <= chain, sorted(outputs - chain)
    assert own <= outputs and downstream == {"results/data/extras/extra_fourier_iou_fig16.nc"}, (own, downstream)
    # redrawing a figure (a plotting change) reruns its notebook only, never a dataset
    fig = run_snakemake(wd, "-n", "results/figures/fig05.png", "--forcerun", "fig05")
    assert fig.returncode == 0, fig.stderr[-2000:]
    stats = (fig.stdout + fig.stderr).split("Job stats")[-1]
    assert re.search(r"^fig05\s+1", stats, re.M) and "analytic_dataset" not in stats and "parameters" not in stats


def test_archive_and_report(quick):
    wd, r = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    a = run_snakemake(wd, "-j1", "archive")
    assert a.returncode == 0, a.stderr[-3000:]
    arch = wd / "results/archive/safebasins-results.tar.gz"
    assert [p.name for p in arch.parent.iterdir()] == [arch.name]  # nothing temporary left
    with tarfile.open(arch) as tar:
        names = tar.getnames()
        members = {n.split("/", 1)[1]: tar.extractfile(n).read() for n in names}
    assert all(n.startswith("safebasins-results/") for n in names)
    for f in DATASETS + RUN.param_files():
        assert f.removeprefix("results/") in members, f
    for k in ("config.resolved.yaml", "environment.lock", "environment.installed.txt", "PROVENANCE.json",
              "CITATION.cff", "README.md", "Snakefile", "ro-crate-metadata.json", "MANIFEST.sha256"):
        assert k in members, k
    manifest = {}
    for line in members["MANIFEST.sha256"].decode().splitlines():
        digest, name = line.split("  ", 1)
        manifest[name] = digest
    assert set(manifest) == set(members) - {"MANIFEST.sha256"}
    for name, digest in manifest.items():
        assert hashlib.sha256(members[name]).hexdigest() == digest, name
    graph = {e["@id"]: e for e in json.loads(members["ro-crate-metadata.json"])["@graph"]}
    root = graph["./"]
    assert "https://w3id.org/ro/wfrun/workflow/0.5" in {c["@id"] for c in root["conformsTo"]}
    assert root["mainEntity"]["@id"] == "Snakefile" and root["license"]["@id"] == "https://spdx.org/licenses/MIT"
    assert set(members) - {"ro-crate-metadata.json"} <= {p["@id"] for p in root["hasPart"]}
    run = graph[root["mentions"]["@id"]]
    assert run["@type"] == "CreateAction" and run["instrument"]["@id"] == "Snakefile"
    assert {x["@id"] for x in run["result"]} == {f.removeprefix("results/") for f in DATASETS}
    for f in DATASETS:
        with xr.open_dataset(wd / f) as ds:
            title = ds.attrs["title"]
        e = graph[f.removeprefix("results/")]
        assert e["name"] == title and "application/x-netcdf" in e["encodingFormat"], f
        assert e["sha256"] == manifest[f.removeprefix("results/")], f
    rep = run_snakemake(wd, "--report", "results/report.html")
    assert rep.returncode == 0, rep.stderr[-3000:]
    assert (wd / "results/report.html").stat().st_size > 10_000


def _compare(ref_wd, wd, files):
    for f in files:
        assert_same_content(load(ref_wd / f), load(wd / f))


def test_j1_and_tiles_identical(quick, tmp_path):
    ref, r = quick
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
    ref, r = quick
    if r.returncode != 0:
        pytest.skip("quick run failed")
    wd = make_sandbox(tmp_path / "kill")
    env = snakemake_env()
    proc = subprocess.Popen(snakemake_cmd(wd, "-j2", *SUBSET), cwd=wd, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    logs = wd / "results/logs/numeric"
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
