"""Reproduction across machines (safebasins.io.reproduction): the verdict on synthetic datasets
shaped like the pipeline's (an F_cr curve stack, a basin mask, an escape chart, a numeric F_cr
bisection) perturbed the way two honest runs differ, and the way a wrong run differs: a value
out of tolerance, a mask changed too much or away from its boundary, a NaN where there was
none, a branch found in one run where F_cr differs.  Then the tree comparison against a results
archive written by safebasins.io.archive, its bad inputs, and the command line."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from click.testing import CliRunner

from safebasins.cli import main
from safebasins.io import archive as sa
from safebasins.io.reproduction import (DIFFERS, IDENTICAL, MISSING, TOLERANCES, WITHIN, ReproductionInputError,
                                        dataset_verdict, variable_kind, verify_reproduction)
from safebasins.io.reproduction import main as module_main

ROOT = Path(__file__).resolve().parents[2]
RTOL = TOLERANCES["slow_flow"].rtol
SHARE = TOLERANCES["mask"].fraction


def fcr(F_SM=None):
    """An analytic F_cr stack over (curve, Omega) with its branches, as theory.critical_forcing."""
    Om = np.linspace(0.5, 1.2, 8)
    F_cr = np.vstack([0.3 * np.abs(1 - Om) + 0.01, 0.2 * np.abs(1 - Om) + 0.02])
    sm = np.where(Om > 0.9, F_cr, np.nan) if F_SM is None else F_SM
    mm = np.where(Om > 0.9, np.nan, F_cr)
    mech = np.where(np.isnan(sm), 1, 3).astype(np.int8)
    return xr.Dataset(
        {"F_cr": (("curve", "Omega"), F_cr), "F_SM": (("curve", "Omega"), sm), "F_MM_0": (("curve", "Omega"), mm),
         "xi_saddle": (("curve", "Omega"), np.where(np.isnan(sm), np.nan, 0.1)),
         "gamma_saddle": (("curve", "Omega"), np.where(np.isnan(sm), np.nan, 0.0), {"units": "rad"}),
         "mechanism": (("curve", "Omega"), mech)},
        coords={"Omega": Om, "xi_max": ("curve", [0.15, 0.242]), "label": ("curve", ["a", "b"])},
        attrs={"title": "F_cr", "xi_max": 0.15, "fourier": "paper", "git_commit": "abc"})


def basin(n=20):
    """An analytic basin: a disc of safe ICs (escapes = False inside) and a boundary curve."""
    q = np.linspace(-1, 1, n)
    Q, P = np.meshgrid(q, q, indexing="ij")
    escapes = Q ** 2 + P ** 2 > 0.5
    t = np.linspace(0, 2 * np.pi, 50)
    return xr.Dataset({"escapes": (("q0", "p0"), escapes), "q0_vertex": ("vertex", np.sqrt(0.5) * np.cos(t)),
                       "kind": ("curve", ["island"])},
                      coords={"q0": q, "p0": q}, attrs={"title": "basin", "F": 0.01})


def chart(n=20):
    """A numeric chart: escape times over (xi_max, q0, p0), inf inside the disc."""
    b = basin(n)
    esc = np.where(b["escapes"].values, 5.0 + b["q0"].values[:, None] ** 2, np.inf)[None]
    return xr.Dataset({"escape_cycle_energy": (("xi_max", "q0", "p0"), esc),
                       "safe_numeric": ("xi_max", [int(np.isinf(esc).sum())]), "iou": ("xi_max", [0.9])},
                      coords={"xi_max": [0.2], "q0": b["q0"], "p0": b["p0"]},
                      attrs={"title": "chart", "cycles": 100, "steps_per_cycle": 16})


def numeric_fcr():
    return xr.Dataset({"F_cr": ("Omega", [0.10, 0.12]), "F_cr_low": ("Omega", [0.0995, 0.1195]),
                       "non_monotone": ("Omega", [False, False])},
                      coords={"Omega": [0.7, 0.9]},
                      attrs={"title": "numeric F_cr", "tol": 1e-3, "criterion": "energy"})


def verdict(old, new):
    return dataset_verdict(old, new, "x.nc")


def test_kinds_follow_the_contract_names():
    """Names of docs/contracts.md land in their kind; F_cr is a bisection only in a dataset with `tol`."""
    f = np.zeros(2)
    assert variable_kind("F_cr", f, {}) == "slow_flow"
    assert variable_kind("F_cr", f, {"tol": 1e-3}) == "numeric_threshold"
    assert variable_kind("F_SM", f, {}) == variable_kind("mechanism", np.zeros(2, np.int8), {}) == "branch"
    assert variable_kind("escape_cycle_energy", f, {}) == variable_kind("escape_cycle_numeric", f, {}) == "escape_time"
    assert variable_kind("escapes", np.zeros(2, bool), {}) == variable_kind("region", np.zeros(2, int), {}) == "mask"
    for name in ("iou", "GIM_true", "safe_numeric", "A_E", "area_continuous", "F_LIM"):
        assert variable_kind(name, f, {}) == "measure", name
    assert variable_kind("q0_vertex", f, {}) == variable_kind("gamma", f, {}) == "curve"
    assert variable_kind("C_level", f, {}) == variable_kind("GIM_closed", f, {}) == "slow_flow"
    assert variable_kind("F_settle", f, {"rtol": 1e-7}) == "numeric_threshold"
    assert variable_kind("orbit_class", np.zeros(2, np.int8), {}) == "exact"
    assert variable_kind("Omega", f, {}, dimension=True) == "exact"


def test_identical_and_provenance_only():
    a = fcr()
    b = fcr()
    b.attrs["git_commit"] = "def"
    assert verdict(a, b).status == IDENTICAL


def test_slow_flow_values_within_and_beyond_tolerance():
    a = fcr()
    b = a.copy(deep=True)
    b["F_cr"][0, 3] *= 1 + 0.1 * RTOL
    v = verdict(a, b)
    assert v.status == WITHIN and v.worst.variable == "F_cr" and v.worst.tolerance == RTOL
    assert 0.05 * RTOL < v.worst.amount < 0.15 * RTOL
    assert "F_cr" in v.lines()[0] and "tolerance" in v.lines()[0]
    b["F_cr"][0, 3] = a["F_cr"][0, 3] * (1 + 10 * RTOL)
    v = verdict(a, b)
    assert v.status == DIFFERS and any(p.startswith("F_cr: relative difference") for p in v.problems), v.problems


def test_near_zero_values_count_on_the_variable_scale():
    """A phase of 4e-16 vs 0 (a saddle on gamma = 0 found with a last-bit shift) is no difference;
    0.01 rad is."""
    a = fcr()
    b = a.copy(deep=True)
    b["gamma_saddle"].values[np.isfinite(b["gamma_saddle"].values)] = 4.4e-16
    assert verdict(a, b).status == WITHIN
    b["gamma_saddle"].values[np.isfinite(b["gamma_saddle"].values)] = 0.01
    assert verdict(a, b).status == DIFFERS


def test_curves_count_on_their_scale():
    """A vertex next to a curve's end moves by 1e-10 (arccos of the tables' last bits): within
    tolerance even where the coordinate itself is near 0; a move of 1e-6 of the scale differs."""
    a = basin()
    b = a.copy(deep=True)
    q = b["q0_vertex"].values
    k = int(np.argmin(np.abs(q)))
    q[k] += 1e-10
    v = verdict(a, b)
    assert v.status == WITHIN and v.worst.kind == "curve" and v.worst.amount < 2e-10
    q[k] += 1e-6
    assert verdict(a, b).status == DIFFERS


def test_damped_threshold_uses_the_dataset_rtol():
    a = xr.Dataset({"F_cr": ("Omega", [0.05, 0.07]), "F_settle": ("Omega", [0.05, 0.07]),
                    "t_escape": ("Omega", [160.0, 33.0])}, coords={"Omega": [0.8, 0.9]},
                   attrs={"title": "damped", "rtol": 1e-7})
    b = a.copy(deep=True)
    b["F_cr"][0] *= 1 + 5e-8
    b["t_escape"][0] *= 1 + 6e-9
    v = verdict(a, b)
    assert v.status == WITHIN and v.worst.variable == "F_cr" and v.worst.tolerance == 1e-7
    b["F_settle"][1] *= 1 + 2e-7
    assert verdict(a, b).status == DIFFERS


def test_nan_where_there_was_none_differs():
    a = fcr()
    b = a.copy(deep=True)
    b["F_cr"][1, 2] = np.nan
    v = verdict(a, b)
    assert v.status == DIFFERS and "NaN" in v.problems[0] and "F_cr" in v.problems[0]
    c = basin()
    d = c.copy(deep=True)
    d["q0_vertex"][7] = np.nan
    assert verdict(c, d).status == DIFFERS


def test_branch_found_in_one_run_only_where_degenerate():
    """The saddle branch of one Omega exists in one run only: legitimate where F_cr agrees (the
    saddle on xi_max: SM and MM_0 give the same F), a difference where F_cr changes with it."""
    a = fcr()
    sm = a["F_SM"].values.copy()
    j = int(np.nonzero(np.isnan(sm[0]))[0][-1])          # the last Omega without a saddle
    sm[0, j] = a["F_cr"].values[0, j]
    b = fcr(F_SM=sm)
    b["F_MM_0"][0, j] = np.nan
    v = verdict(a, b)
    assert v.status == WITHIN, v.problems
    b["F_cr"][0, j] *= 1.01
    v = verdict(a, b)
    assert v.status == DIFFERS
    assert any(p.startswith("F_SM: NaN") for p in v.problems) and any("mechanism" in p for p in v.problems)


def test_mask_boundary_pixel_interior_pixel_and_too_many():
    a = basin()
    esc = a["escapes"].values
    edge = np.argwhere(~esc & (np.roll(esc, 1, 0) | np.roll(esc, -1, 0)))  # safe pixels next to escaping ones
    b = a.copy(deep=True)
    b["escapes"].values[tuple(edge[0])] = True
    v = verdict(a, b)
    assert v.status == WITHIN and v.worst.variable == "escapes" and v.worst.what == "of entries"
    b = a.copy(deep=True)
    b["escapes"].values[10, 10] = True                     # the centre of the disc, far from its boundary
    v = verdict(a, b)
    assert v.status == DIFFERS and "away from any boundary" in v.problems[0]
    b = a.copy(deep=True)
    n = int(np.ceil(2 * SHARE * esc.size))
    for i, j in edge[:n]:
        b["escapes"].values[i, j] = True
    assert len(edge) >= n
    v = verdict(a, b)
    assert v.status == DIFFERS and "more than the tolerated" in v.problems[0]


def test_escape_times_change_where_both_escape_not_across_the_basin():
    a = chart()
    t = a["escape_cycle_energy"].values
    i = tuple(np.argwhere(np.isfinite(t))[0])
    b = a.copy(deep=True)
    b["escape_cycle_energy"].values[i] += 17.0           # escapes in both, later
    assert verdict(a, b).status == WITHIN
    b = a.copy(deep=True)
    b["escape_cycle_energy"].values[0, 10, 10] = 3.0     # the basin's centre escapes
    assert verdict(a, b).status == DIFFERS


def test_measures_take_the_mask_share():
    a = chart()
    b = a.copy(deep=True)
    b["iou"][0] = 0.9 * (1 + 0.5 * TOLERANCES["measure"].rtol)
    assert verdict(a, b).status == WITHIN
    b["iou"][0] = 0.9 * (1 + 2 * TOLERANCES["measure"].rtol)
    assert verdict(a, b).status == DIFFERS


def test_numeric_threshold_uses_the_dataset_tol():
    a = numeric_fcr()
    b = a.copy(deep=True)
    b["F_cr"][0] += 0.5e-3
    v = verdict(a, b)
    assert v.status == WITHIN and v.worst.kind == "numeric_threshold" and v.worst.tolerance == 1e-3
    b["F_cr"][0] += 1e-3
    assert verdict(a, b).status == DIFFERS


def test_exact_kinds_labels_and_structure():
    a = fcr()
    b = a.copy(deep=True)
    b = b.assign_coords(label=("curve", ["a", "c"]))
    assert verdict(a, b).status == DIFFERS
    c = basin()
    d = c.copy(deep=True)
    d["kind"].values[0] = "saddle"
    assert verdict(c, d).status == DIFFERS
    assert verdict(c, c.drop_vars("q0_vertex")).status == DIFFERS
    assert verdict(c, c.isel(vertex=slice(0, 40))).status == DIFFERS
    e = numeric_fcr()
    f = e.copy(deep=True)
    f["non_monotone"][1] = True
    assert verdict(e, f).status == DIFFERS


def test_attributes_numbers_by_tolerance_text_exactly():
    a = basin()
    b = a.copy(deep=True)
    b.attrs["F"] = 0.01 * (1 + 0.1 * RTOL)
    assert verdict(a, b).status == WITHIN
    b.attrs["F"] = 0.011
    assert verdict(a, b).status == DIFFERS
    b = a.copy(deep=True)
    b.attrs["fourier"] = "exact"
    assert verdict(a, b).status == DIFFERS
    b = a.copy(deep=True)
    b.attrs["date_created"] = "2030"                    # provenance only in the new run
    assert verdict(a, b).status == IDENTICAL


# ---------------------------------------------------------------- trees, archives, bad input

def _results(root: Path, perturb=None) -> Path:
    data = root / "results" / "data"
    for rel, ds in (("analytic/fcr_fig01.nc", fcr()), ("analytic/basin_fig05.nc", basin()),
                    ("numeric/chart_fig13.nc", chart())):
        if perturb:
            ds = perturb(rel, ds)
        if ds is None:
            continue
        (data / rel).parent.mkdir(parents=True, exist_ok=True)
        ds.to_netcdf(data / rel)
    return root / "results"


def _archive(tmp_path: Path) -> Path:
    res = _results(tmp_path / "ref")
    params = res / "params" / "fig01.yaml"
    params.parent.mkdir(parents=True)
    params.write_text(yaml.safe_dump({"experiment": "fig01"}))
    src = tmp_path / "src"
    src.mkdir()
    (src / "Snakefile").write_text("rule a:\n    output: 'x'\n")
    (src / "CITATION.cff").write_bytes((ROOT / "CITATION.cff").read_bytes())
    lock = tmp_path / "environment.lock"
    lock.write_text("numpy==2.0.0 \\\n    --hash=sha256:00\n")
    return sa.write_archive(tmp_path / "archive" / "safebasins-results.tar.gz", sorted(res.rglob("*.nc")), [params],
                            lock, {"seed": 1}, workflow=src / "Snakefile", citation=src / "CITATION.cff",
                            results_dir=res)


def test_archive_against_a_new_tree(tmp_path):
    arch = _archive(tmp_path)

    def honest(rel, ds):
        if rel.endswith("fcr_fig01.nc"):
            ds["F_cr"] = ds["F_cr"] * (1 + 1e-12)
        return ds

    rep = verify_reproduction(arch, _results(tmp_path / "new", honest))
    status = {v.dataset: v.status for v in rep.verdicts}
    assert status == {"analytic/fcr_fig01.nc": WITHIN, "analytic/basin_fig05.nc": IDENTICAL,
                      "numeric/chart_fig13.nc": IDENTICAL}
    assert rep.reproduced and list(rep.lines())[-1].endswith("REPRODUCED")
    # the data directory itself and the results directory both work, the crate extracted too
    assert verify_reproduction(tmp_path / "ref" / "results" / "data", tmp_path / "new" / "results" / "data").reproduced

    def wrong(rel, ds):
        if rel.endswith("basin_fig05.nc"):
            ds["escapes"][10, 10] = True
        return None if rel.endswith("chart_fig13.nc") else ds

    rep = verify_reproduction(arch, _results(tmp_path / "wrong", wrong))
    status = {v.dataset: v.status for v in rep.verdicts}
    assert status["analytic/basin_fig05.nc"] == DIFFERS and status["numeric/chart_fig13.nc"] == MISSING
    assert not rep.reproduced and list(rep.lines())[-1].endswith("NOT REPRODUCED")


def test_bad_input_names_the_argument(tmp_path):
    new = _results(tmp_path / "new")
    with pytest.raises(ReproductionInputError, match="REFERENCE .*nowhere.tar.gz does not exist"):
        verify_reproduction(tmp_path / "nowhere.tar.gz", new)
    junk = tmp_path / "junk.tar.gz"
    junk.write_bytes(b"not a tarball")
    with pytest.raises(ReproductionInputError, match="REFERENCE .*junk.tar.gz is not a results archive"):
        verify_reproduction(junk, new)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ReproductionInputError, match="NEW_DIR .*empty: no netCDF datasets"):
        verify_reproduction(new, empty)
    with pytest.raises(ReproductionInputError, match="NEW_DIR .*missing does not exist"):
        verify_reproduction(new, tmp_path / "missing")


def test_command_line(tmp_path):
    arch = _archive(tmp_path)
    new = _results(tmp_path / "new")
    r = CliRunner().invoke(main, ["verify-reproduction", str(arch), str(new / "data")])
    assert r.exit_code == 0, r.output
    assert "identical         analytic/fcr_fig01.nc" in r.output and "-> REPRODUCED" in r.output

    def wrong(rel, ds):
        if rel.endswith("fcr_fig01.nc"):
            ds["F_cr"] = ds["F_cr"] * 1.001
        return ds

    r = CliRunner().invoke(main, ["verify-reproduction", "--quiet", str(arch), str(_results(tmp_path / "w", wrong))])
    assert r.exit_code == 1 and "DIFFERS           analytic/fcr_fig01.nc" in r.output
    assert "identical" not in r.output.replace("0 identical", "").replace("2 identical", "")
    r = CliRunner().invoke(main, ["verify-reproduction", str(tmp_path / "none.tar.gz"), str(new)])
    assert r.exit_code == 2 and "ARCHIVE_OR_DIR" in r.output and "none.tar.gz does not exist" in r.output
    r = CliRunner().invoke(main, ["verify-reproduction", str(arch), str(tmp_path / "none")])
    assert r.exit_code == 2 and "NEW_DIR" in r.output
    assert module_main([str(arch), str(new)]) == 0
    assert module_main([str(arch)]) == 2
