"""`safebasins check-config`: a configuration checked as the pipeline would, nothing run.  Each
kind of mistake (YAML syntax, a key given twice, the schema, a kind's or the well's plan-time
check, the cost guard, a file that is not a mapping or not UTF-8) gives exit status 1 and names
the file and line or the key; a good overlay of the checkout's config/config.yaml passes."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from safebasins.cli import main
from safebasins.cli.check_config import key_location
from safebasins.pipeline.config import REPO_ROOT

SCRIPT = Path(sys.executable).with_name("safebasins")
BASE = REPO_ROOT / "config" / "config.yaml"
PENDULUM = ("experiments:\n  mine:\n    kind: basin_chart\n    well: pendulum\n    F: 0.05\n    Omega: 0.9\n"
            "    Psi: pi\n    grid: {q0: [-1, 1], p0: [-1, 1], n: 10}\n    xi_max: [1.0, XI]\n")


def check(tmp_path, text, *args):
    """Run check-config (in-process) on a file holding ``text``: (the file, the result)."""
    f = tmp_path / "mine.yaml"
    f.write_bytes(text if isinstance(text, bytes) else text.encode())
    return f, CliRunner().invoke(main, ["check-config", *args, str(f)], catch_exceptions=False)


@pytest.fixture
def in_checkout(monkeypatch):
    monkeypatch.chdir(REPO_ROOT)


def failed(res, *texts):
    assert res.exit_code == 1, res.output
    assert "Traceback" not in res.output
    for t in texts:
        assert t in res.output, (t, res.output)
    return res.output


def test_a_good_overlay_is_valid_over_the_checkouts_config(in_checkout, tmp_path):
    f, res = check(tmp_path, PENDULUM.replace("XI", "1.5"))
    assert res.exit_code == 0, res.output
    assert f"{f} merged over config/config.yaml: valid (" in res.output
    assert "safebasins cost estimate (this configuration)" in res.output
    # the quick config too, and the paper's config on its own
    res = CliRunner().invoke(main, ["check-config", "config/quick.yaml"])
    assert res.exit_code == 0 and "config/quick.yaml merged over config/config.yaml: valid" in res.output, res.output
    res = CliRunner().invoke(main, ["check-config", "--no-base", "config/config.yaml"])
    assert res.exit_code == 0 and res.output.startswith("config/config.yaml: valid ("), res.output


def test_yaml_syntax_error_names_file_line_and_column(in_checkout, tmp_path):
    f, res = check(tmp_path, "numerics:\n  steps_per_cycle: 16\nfigures:\n  fig13: {cycles: [1, 2}\n")
    failed(res, f"config file {f}, line 4, column 24: not valid YAML", "expected ',' or ']'")
    f, res = check(tmp_path, "figures:\n  fig13:\n\tcycles: 3\n")
    failed(res, f"config file {f}, line 3, column 1: not valid YAML")


def test_a_key_given_twice_names_the_key_and_both_lines(in_checkout, tmp_path):
    f, res = check(tmp_path, "figures:\n  fig13:\n    cycles: 10\n  fig14: {cycles: 5}\n  fig13: {cycles: 20}\n")
    failed(res, f"config file {f}, line 5: key figures.fig13 is given twice (first on line 2)")


def test_schema_error_names_the_key_path_and_where_the_file_sets_it(in_checkout, tmp_path):
    f, res = check(tmp_path, "numerics: {steps_per_cycle: 16}\nfigures:\n  fig13:\n    grid: {n: 24}\n    cycles: -5\n")
    failed(res, "config key figures.fig13.cycles: -5 is less than the minimum of 1", f"(set at {f}, line 5)")
    f, res = check(tmp_path, "figures:\n  fig13: {cycle: 5}\n")
    failed(res, "config key figures.fig13.cycle: unknown key 'cycle'", f"(set at {f}, line 2)")
    # a missing key: the block that lacks it
    f, res = check(tmp_path, "experiments:\n  mine:\n    kind: basin_chart\n    F: 0.05\n")
    failed(res, "config key experiments.mine.", "missing required key", f"(in the block at {f}, line 2)")


def test_plan_time_checks_of_the_pipeline_apply(in_checkout, tmp_path):
    # above the pendulum's barrier energy 2 (the well's check, not the schema's)
    f, res = check(tmp_path, PENDULUM.replace("XI", "3.0"))
    failed(res, "config key experiments.mine.xi_max[1]: 3.0 must be at most the barrier energy 2 of the pendulum well",
           f"(set at {f}, line 9)")
    # a kind written for the quartic only, given another well
    _, res = check(tmp_path, "figures:\n  fig18: {well: cubic}\n")
    failed(res, "config key figures.fig18.well: kind 'strobe' is written for the paper's quartic only")
    # the cost guard: the pipeline would refuse to start
    f, res = check(tmp_path, "numerics: {budget_core_hours: 0.001}\n")
    failed(res, "config key numerics.budget_core_hours:", "above the budget of 0.001 core-hours",
           f"(set at {f}, line 1)")


def test_files_that_are_no_mapping_or_no_text_are_named(in_checkout, tmp_path):
    f, res = check(tmp_path, "- a\n- b\n")
    failed(res, f"config file {f}: must hold a mapping of keys", "got a list")
    f, res = check(tmp_path, b"figures: \xff\xfe\n")
    failed(res, f"config file {f}: not UTF-8 text (byte 9")


def test_outside_a_checkout_the_base_is_named_or_missing_said(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    _, res = check(tmp_path, PENDULUM.replace("XI", "1.5"))
    failed(res, "missing required key 'figures'", "checked without a base configuration: no config/config.yaml")
    f, res = check(tmp_path, PENDULUM.replace("XI", "1.5"), "--base", str(BASE))
    assert res.exit_code == 0 and f"{f} merged over {BASE}: valid" in res.output, res.output
    res = CliRunner().invoke(main, ["check-config", "--base", str(BASE), "--no-base", str(f)])
    assert res.exit_code == 2 and "give either --base or --no-base" in res.output


def test_key_location_takes_the_last_file_that_sets_the_key(tmp_path):
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    a.write_text("figures:\n  fig13:\n    cycles: 1\n    xi_max: [0.1, 0.2]\n")
    b.write_text("# overlay\nfigures:\n  fig13: {cycles: 2}\n")
    assert key_location("figures.fig13.cycles", [a, b]) == (str(b), 3, True)
    assert key_location("figures.fig13.xi_max[1]", [a, b]) == (str(a), 4, True)
    assert key_location("figures.fig13.grid", [a, b]) == (str(b), 3, False)
    assert key_location("experiments.x", [a, b]) is None


def test_the_console_script_runs_it_and_exits_1_on_a_bad_file(tmp_path):
    assert SCRIPT.exists(), f"no console script {SCRIPT}: reinstall the package (pip install -e .)"
    f = tmp_path / "bad.yaml"
    f.write_text("figures: [1, 2\n")
    res = subprocess.run([str(SCRIPT), "check-config", str(f)], cwd=REPO_ROOT, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 1 and f"Error: config file {f}, line 2, column 1: not valid YAML" in res.stderr, res
    assert res.stdout == "" and "Traceback" not in res.stderr
